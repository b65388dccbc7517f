option(OMNISLAM_WERROR "Treat compiler warnings as errors" OFF)

# The one warnings policy of the project, applied to every target it builds.
function(omnislam_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  if(OMNISLAM_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# Runs at install time (cmake_install.cmake), so the paths follow `--prefix`. Installs:
#   PREFIX/lib/systemd/system/omnislamd.service  ExecStart pointing at PREFIX/bin and the
#                                                configuration directory below
#   /etc/omnislam (prefix /usr) or PREFIX/etc/omnislam: omnislamd.yaml, thesis-2008.yaml,
#                                                cyclonedds.xml; an edited file is kept and
#                                                the new one installed beside it as *.new
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(omnislam_confdir "/etc/omnislam")
else()
  set(omnislam_confdir "${CMAKE_INSTALL_PREFIX}/etc/omnislam")
endif()

file(READ "${OMNISLAM_DEPLOY_DIR}/omnislamd.service" omnislam_unit)
string(REPLACE "/usr/bin/omnislamd" "${CMAKE_INSTALL_PREFIX}/${OMNISLAM_BINDIR}/omnislamd" omnislam_unit
               "${omnislam_unit}")
string(REPLACE "/etc/omnislam/" "${omnislam_confdir}/" omnislam_unit "${omnislam_unit}")
file(WRITE "${OMNISLAM_STAGING_DIR}/omnislamd.service" "${omnislam_unit}")
# file(INSTALL) prepends DESTDIR itself.
file(INSTALL "${OMNISLAM_STAGING_DIR}/omnislamd.service" DESTINATION "${CMAKE_INSTALL_PREFIX}/lib/systemd/system")

foreach(name omnislamd.yaml thesis-2008.yaml cyclonedds.xml)
  set(source "${OMNISLAM_DEPLOY_DIR}/${name}")
  set(target "$ENV{DESTDIR}${omnislam_confdir}/${name}")
  if(NOT EXISTS "${source}")
    continue()
  endif()
  if(EXISTS "${target}")
    file(SHA256 "${source}" new_hash)
    file(SHA256 "${target}" old_hash)
    if(NOT new_hash STREQUAL old_hash)
      message(STATUS "Keeping the edited ${target}; the new default goes to ${name}.new")
      file(READ "${source}" content)
      file(WRITE "${OMNISLAM_STAGING_DIR}/${name}.new" "${content}")
      file(INSTALL "${OMNISLAM_STAGING_DIR}/${name}.new" DESTINATION "${omnislam_confdir}")
      continue()
    endif()
  endif()
  file(INSTALL "${source}" DESTINATION "${omnislam_confdir}")
endforeach()

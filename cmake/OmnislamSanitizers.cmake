# Sanitizer builds (scripts/test runs build-asan and build-tsan) and the libFuzzer targets.
set(OMNISLAM_SANITIZE "" CACHE STRING
    "Sanitizers applied to every target: address,undefined or thread (empty: none)")
option(OMNISLAM_BUILD_FUZZERS "Build the libFuzzer targets of tests/fuzz (clang only)" OFF)

if(OMNISLAM_SANITIZE)
  if(OMNISLAM_SANITIZE MATCHES "thread" AND OMNISLAM_SANITIZE MATCHES "address")
    message(FATAL_ERROR "OMNISLAM_SANITIZE: ThreadSanitizer cannot be combined with AddressSanitizer")
  endif()
  # Any finding fails the test that triggered it, UBSan included.
  add_compile_options(-fsanitize=${OMNISLAM_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all -g)
  add_link_options(-fsanitize=${OMNISLAM_SANITIZE})
  if(OMNISLAM_SANITIZE MATCHES "thread" AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU"
     AND CMAKE_CXX_COMPILER_VERSION VERSION_GREATER_EQUAL 12)
    # GCC 12 warns that TSan does not model std::atomic_thread_fence; the queues use acquire/
    # release operations, which it does model.
    add_compile_options(-Wno-tsan)
  endif()
endif()

if(OMNISLAM_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "OMNISLAM_BUILD_FUZZERS needs clang (libFuzzer): configure with CXX=clang++")
  endif()
  # Coverage feedback from the parsers in the libraries; the fuzz targets link the driver.
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

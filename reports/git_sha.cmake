# Writes OUT (a header defining HAIRBENCH_GIT_SHA) with the commit of SOURCE_DIR, at every
# build rather than once at configure time, so that a report names the commit its binary
# was built from, also after later commits and incremental builds.
# The file is rewritten only when the commit changes, so an unchanged commit rebuilds nothing.
execute_process(COMMAND git rev-parse --short=12 HEAD
                WORKING_DIRECTORY "${SOURCE_DIR}"
                OUTPUT_VARIABLE sha OUTPUT_STRIP_TRAILING_WHITESPACE
                ERROR_QUIET)
if(sha STREQUAL "")
  set(sha "unknown")
endif()
set(text "#define HAIRBENCH_GIT_SHA \"${sha}\"\n")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUT}" "${text}")
endif()

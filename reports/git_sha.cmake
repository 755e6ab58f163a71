# Writes OUT (a header defining HAIRBENCH_GIT_SHA) with the commit of SOURCE_DIR, at every
# build rather than once at configure time: a report run where git cannot answer (a copy of
# the tree without .git) names the commit the binary was built from, not an older one.
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

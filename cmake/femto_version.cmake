# Writes OUTPUT (generated/femto_version.h) from SOURCE_DIR/core/version.h.in with the commit the
# sources are at (git describe). Run at configure time and again by every build (the target
# femto_version), so that `femto --version` and the run records name the commit that was built,
# not the one last configured; the file is rewritten only when its text changes.
# Inputs: SOURCE_DIR, OUTPUT, PROJECT_VERSION, FEMTO_INSTRUCTION_SET.
execute_process(COMMAND git describe --always --dirty
  WORKING_DIRECTORY ${SOURCE_DIR} OUTPUT_VARIABLE FEMTO_GIT_DESCRIBE
  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT FEMTO_GIT_DESCRIBE)
  set(FEMTO_GIT_DESCRIBE "unknown")
endif()
configure_file(${SOURCE_DIR}/core/version.h.in ${OUTPUT} @ONLY)

# Writes OUT from TEMPLATE with the source's commit as it is at build time (run by
# the target rocklab_build_info on every build). The file is replaced only when the
# commit changed, so an unchanged tree rebuilds nothing. A tree with uncommitted
# changes gets "-modified", so a page never claims a commit it was not built from.
execute_process(COMMAND git -C "${SOURCE_DIR}" rev-parse --short=12 HEAD
  OUTPUT_VARIABLE ROCKLAB_SOURCE_COMMIT OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE git_rc)
if(NOT git_rc EQUAL 0)
  set(ROCKLAB_SOURCE_COMMIT "")
else()
  execute_process(COMMAND git -C "${SOURCE_DIR}" diff-index --quiet HEAD --
    RESULT_VARIABLE dirty_rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT dirty_rc EQUAL 0)
    string(APPEND ROCKLAB_SOURCE_COMMIT "-modified")
  endif()
endif()
configure_file("${TEMPLATE}" "${OUT}.new" @ONLY)
file(COPY_FILE "${OUT}.new" "${OUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUT}.new")

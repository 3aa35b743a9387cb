# hairpipe_warnings(<target>): the project's warning set, applied to our own
# targets only (third-party headers are included as SYSTEM by their targets).
function(hairpipe_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow=local
                         -Wno-unused-parameter)
  if(HAIRPIPE_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  hairpipe_sanitizer_defaults(${target})  # cmake/Sanitizers.cmake
endfunction()

# hairpipe_embed_files(<target> DIR <folder> PATTERN <glob> INCLUDE <header>
#                      TYPE <entry type> FUNCTION <name>)
# Compiles every file of DIR matching PATTERN into <target> as strings, through
# a generated <FUNCTION>.cpp that defines `const std::vector<TYPE>& FUNCTION()`
# (declared in INCLUDE; the script is cmake/EmbedFiles.cmake). The file is
# regenerated whenever an input changes, and a file added to DIR is picked up
# at the next build (CONFIGURE_DEPENDS). Used for the preview's shaders/, the
# scene schema's pipeline/scene/keys/ and the scene fuzz target.
set(HAIRPIPE_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/EmbedFiles.cmake)

function(hairpipe_embed_files target)
  cmake_parse_arguments(E "" "DIR;PATTERN;INCLUDE;TYPE;FUNCTION" "" ${ARGN})
  file(GLOB _inputs CONFIGURE_DEPENDS "${E_DIR}/${E_PATTERN}")
  set(_out ${CMAKE_CURRENT_BINARY_DIR}/${E_FUNCTION}.cpp)
  add_custom_command(OUTPUT ${_out}
    COMMAND ${CMAKE_COMMAND} -DDIR=${E_DIR} -DPATTERN=${E_PATTERN} -DOUTPUT=${_out} -DINCLUDE=${E_INCLUDE}
            -DTYPE=${E_TYPE} -DFUNCTION=${E_FUNCTION} -P ${HAIRPIPE_EMBED_SCRIPT}
    DEPENDS ${_inputs} ${HAIRPIPE_EMBED_SCRIPT}
    COMMENT "Embedding ${E_DIR}/${E_PATTERN} into ${target}"
    VERBATIM)
  target_sources(${target} PRIVATE ${_out})
endfunction()

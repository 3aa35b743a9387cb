# HAIRPIPE_SANITIZE=ON: AddressSanitizer + UndefinedBehaviorSanitizer for
# hairpipe's own code (every target of this project; the Debian libraries it
# links are not instrumented). Any report aborts the process: ASan halts on the
# first error by default, -fno-sanitize-recover makes UBSan do the same.
# Build it in a second folder, e.g.
#   cmake -S . -B build-asan -DHAIRPIPE_SANITIZE=ON && cmake --build build-asan -j2
# or just run tools/sanitize/run (docs/hardening.md).
option(HAIRPIPE_SANITIZE "Build with AddressSanitizer + UndefinedBehaviorSanitizer" OFF)

if(HAIRPIPE_SANITIZE)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    message(FATAL_ERROR "HAIRPIPE_SANITIZE needs GCC or Clang")
  endif()
  # -g1: line tables for readable reports at a fraction of full debug info's cost.
  # -O1 (after the build type's -O3, so it wins): instrumented code compiles
  # faster at -O1, and the compile dominates the CI budget; the fast tests
  # barely notice the slower code.
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer
                      -fno-sanitize-recover=all -g1 -O1)
  add_link_options(-fsanitize=address,undefined)
  # Embedded runtime defaults (halt on error, exit code, leak suppressions),
  # so a sanitized binary behaves the same whether CTest, a test's
  # subprocess or a developer's shell starts it.
  set(HAIRPIPE_SANITIZER_DEFAULTS ${PROJECT_SOURCE_DIR}/tools/sanitize/defaults.cpp)
endif()

# hairpipe_sanitizer_defaults(<target>): links the runtime defaults into an
# executable of a sanitized build (no-op otherwise). Called by
# hairpipe_warnings() for every executable, so new executables get it too.
function(hairpipe_sanitizer_defaults target)
  if(NOT HAIRPIPE_SANITIZE)
    return()
  endif()
  get_target_property(_type ${target} TYPE)
  if(_type STREQUAL "EXECUTABLE")
    target_sources(${target} PRIVATE ${HAIRPIPE_SANITIZER_DEFAULTS})
  endif()
endfunction()

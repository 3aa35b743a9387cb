// Runtime defaults of the sanitizer build (HAIRPIPE_SANITIZE=ON, see
// cmake/Sanitizers.cmake), linked into every executable of that build. The
// sanitizer runtimes call these hooks at start-up; ASAN_OPTIONS,
// UBSAN_OPTIONS and LSAN_OPTIONS in the environment still override them.
//
// exitcode=86: a sanitizer report must never read as one of hairpipe's own
// exit codes (1 scene/usage error, 2 a frame failed), or a hostile-input test
// expecting "exit 1" would pass on a heap overflow.

extern "C" {

const char* __asan_default_options() {
    return "halt_on_error=1:abort_on_error=0:exitcode=86:detect_leaks=1:"
           "detect_stack_use_after_return=0:strict_string_checks=1:"
           "check_initialization_order=1";
}

const char* __ubsan_default_options() { return "halt_on_error=1:print_stacktrace=1:exitcode=86"; }

const char* __lsan_default_options() { return "exitcode=86"; }

// Built-in leak suppressions: none. The list lives in tools/sanitize/lsan.supp
// (one reviewed entry per third-party library, each with its reason), which
// tools/sanitize/run and tools/fuzz/run pass through LSAN_OPTIONS so that
// subprocesses started by tests see it too.
const char* __lsan_default_suppressions() { return ""; }

}  // extern "C"

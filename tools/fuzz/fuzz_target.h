// Shared by the libFuzzer targets (tools/fuzz/fuzz_*.cpp) and their
// regression test (tests/test_fuzz_regressions.cpp), so that a kept crasher
// goes through exactly the code the fuzzer ran.
//
// HP_FUZZ_TARGET(name) opens a target's entry point: LLVMFuzzerTestOneInput
// in a fuzz build; the test defines it first to give each target its own
// function name (fuzz_<name>) in one executable.
// HP_FUZZ_CHECK(cond) states a property every input must keep; a violation
// throws std::logic_error, which is not a hairpipe error and so escapes the
// target: a crash for libFuzzer, a failed EXPECT_NO_THROW in the test.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>

#ifndef HP_FUZZ_TARGET
#define HP_FUZZ_TARGET(name) extern "C" int LLVMFuzzerTestOneInput
#endif

#define HP_FUZZ_CHECK(cond) \
    do { \
        if (!(cond)) throw std::logic_error("fuzz property violated: " #cond); \
    } while (0)

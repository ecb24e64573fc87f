// Whether this test binary was built with a sanitizer (scripts/sanitize.sh), for the few tests
// that cannot run under one: AddressSanitizer reserves terabytes of address space at start, so a
// test of a limit on the address space (ulimit -v, prlimit --as) cannot start the program at all.
//
//   if (eikon::test::kAddressSanitizer) GTEST_SKIP() << "why";
#pragma once

namespace eikon::test {

#if defined(__SANITIZE_ADDRESS__)  // GCC
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)  // Clang
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

/// The reason given by the tests skipped under AddressSanitizer.
inline constexpr const char* kNoAddressSpaceLimitUnderAsan =
    "AddressSanitizer reserves terabytes of address space at start: the program cannot run "
    "under an address-space limit (RLIMIT_AS)";

}  // namespace eikon::test

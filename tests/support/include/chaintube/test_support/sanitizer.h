// Whether the test runs under AddressSanitizer (the asan preset): tests that repeat the same paths
// many times run fewer repetitions there, where they are for memory and UB errors. Header-only.
#pragma once

namespace chaintube::test_support {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kUnderAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kUnderAddressSanitizer = true;
#else
inline constexpr bool kUnderAddressSanitizer = false;
#endif
#else
inline constexpr bool kUnderAddressSanitizer = false;
#endif

} // namespace chaintube::test_support

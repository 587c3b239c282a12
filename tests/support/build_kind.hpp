#pragma once
// Which build the tests run in: the sanitizer build (scripts/test.sh's build-asan/) is 50–100× slower
// on allocation-heavy inputs (full unwinding on every malloc), so a few size-driven tests run a
// smaller case there; the release build runs the full size.

namespace matbake::test {

#ifdef MATBAKE_SANITIZED
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif

}  // namespace matbake::test

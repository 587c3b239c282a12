#pragma once
// Large buffers backed by 2 MiB pages where the kernel allows it (transparent huge pages in
// "madvise" mode, Debian's default): a 48 MiB image is then 24 page faults instead of 12,288. The
// faults of fresh buffers were a third of a build's time (docs/performance.md). Advice only: where
// it is refused, memory is as before.
#include <cstddef>
#include <vector>

namespace matbake::image {

// Advises MADV_HUGEPAGE on the 2 MiB-aligned part of [data, data + bytes); call it before the
// memory is first touched. Does nothing below a few MiB.
void advise_huge_pages(void* data, std::size_t bytes);

// v.reserve(n), the new storage advised before anything is written to it.
template <class T>
void reserve_advised(std::vector<T>& v, std::size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  advise_huge_pages(v.data(), v.capacity() * sizeof(T));
}

}  // namespace matbake::image

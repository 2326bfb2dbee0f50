// Whole-image host buffers on transparent huge pages: the hit records' populated memory and the film's channels.
#pragma once

#include <cstddef>
#include <vector>

namespace algray {

// Asks the kernel to back the 2 MB-aligned part of [data, data + bytes) with transparent huge pages (THP, which
// Debian's kernels grant in "madvise" mode). Call it before the memory is first written; a no-op elsewhere.
void advise_huge_pages(void* data, std::size_t bytes);

// v becomes n copies of value, in a buffer that asked for huge pages before it was written: at 1024^2 a film's
// 16 MB of RGBA is then 8 page faults, clears and frees instead of 4096.
template <typename T>
void assign_on_huge_pages(std::vector<T>& v, std::size_t n, const T& value) {
  std::vector<T>().swap(v);
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
  v.assign(n, value);
}

// Page-aligned anonymous memory, every page faulted in as it is made, so that the kernel's threads take no
// faults on the render's path (a CL_MEM_USE_HOST_PTR buffer's host side). From 2 MB up it is 2 MB-aligned and on
// huge pages where granted: 32 MB of hit records then populate in about a quarter of the time and unmap in a
// twentieth (bench/RESULTS.md); where huge pages are refused the same calls give 4 KB pages.
class PopulatedPages {
 public:
  explicit PopulatedPages(std::size_t bytes);
  PopulatedPages(PopulatedPages&& other) noexcept;
  PopulatedPages& operator=(PopulatedPages&&) = delete;
  PopulatedPages(const PopulatedPages&) = delete;
  ~PopulatedPages();
  void* data() const { return data_; }

 private:
  void* data_ = nullptr;  // page-aligned (2 MB-aligned when large), bytes_ long
  void* base_ = nullptr;  // the whole mapping, mapped_ long
  std::size_t bytes_ = 0;
  std::size_t mapped_ = 0;
};

}  // namespace algray

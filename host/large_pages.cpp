// Transparent huge pages for whole-image buffers, and populated page-aligned memory for zero-copy OpenCL buffers.
#include "large_pages.h"

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <new>
#include <utility>

namespace algray {

namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kPage = 4096;

std::uintptr_t round_up(std::uintptr_t v, std::size_t to) { return (v + to - 1) / to * to; }

void* map_anonymous(std::size_t bytes, int extra_flags) {
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | extra_flags, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  return p;
}

}  // namespace

void advise_huge_pages(void* data, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  const auto start = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = round_up(start, kHugePage), end = (start + bytes) / kHugePage * kHugePage;
  // A refusal (THP "never", or no THP in the kernel) leaves 4 KB pages, which are correct, only slower.
  if (data && end > first) ::madvise(reinterpret_cast<void*>(first), end - first, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

PopulatedPages::PopulatedPages(std::size_t bytes) : bytes_(std::max<std::size_t>(bytes, 1)) {
  if (bytes_ < kHugePage) {
    base_ = data_ = map_anonymous(bytes_, MAP_POPULATE);
    mapped_ = bytes_;
    return;
  }
  mapped_ = round_up(bytes_, kHugePage) + kHugePage;  // room to move the start up to a 2 MB boundary
  base_ = map_anonymous(mapped_, 0);
  data_ = reinterpret_cast<void*>(round_up(reinterpret_cast<std::uintptr_t>(base_), kHugePage));
  advise_huge_pages(data_, round_up(bytes_, kHugePage));
#ifdef MADV_POPULATE_WRITE
  if (::madvise(data_, bytes_, MADV_POPULATE_WRITE) == 0) return;
#endif
  // Kernels before 5.14: a write per page faults the range in (2 MB at a time where huge pages are granted).
  for (std::size_t offset = 0; offset < bytes_; offset += kPage) static_cast<volatile char*>(data_)[offset] = 0;
}

PopulatedPages::PopulatedPages(PopulatedPages&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)),
      base_(std::exchange(other.base_, nullptr)),
      bytes_(std::exchange(other.bytes_, 0)),
      mapped_(std::exchange(other.mapped_, 0)) {}

PopulatedPages::~PopulatedPages() {
  if (base_) ::munmap(base_, mapped_);
}

}  // namespace algray

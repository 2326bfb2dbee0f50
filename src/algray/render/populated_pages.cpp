// Host memory with every page faulted in ahead (populated_pages.h).
#include "algray/render/populated_pages.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <new>
#include <utility>

namespace algray {

PopulatedPages::PopulatedPages(std::size_t bytes) : bytes_(std::max<std::size_t>(bytes, 1)) {
  void* p = ::mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  data_ = p;
  ::madvise(p, bytes_, MADV_NOHUGEPAGE);  // advice only: a kernel without transparent huge pages refuses it
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  for (std::size_t at = 0; at < bytes_; at += page) static_cast<volatile char*>(p)[at] = 0;
}

PopulatedPages::PopulatedPages(PopulatedPages&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), bytes_(std::exchange(other.bytes_, 0)) {}

PopulatedPages::~PopulatedPages() {
  if (data_) ::munmap(data_, bytes_);
}

}  // namespace algray

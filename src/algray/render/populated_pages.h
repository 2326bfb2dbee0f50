// Host memory with every page faulted in ahead, for the buffers the kernels write through host pointers.
#pragma once

#include <cstddef>

namespace algray {

// Page-aligned anonymous memory with every page faulted in as it is made, one write a page, on the thread that makes
// it (one beside the render's: a tile's hit records are made while the device starts or the programs load). Not
// MAP_POPULATE: its one system call holds the process's memory-map lock while it faults 32 MB in (a 1024^2 preview),
// and the thread loading the programs, whose allocations need that lock, waited for it: 8 ms of the 15 ms a program
// took to load from the disk cache. 4 KB pages on purpose (MADV_NOHUGEPAGE, whatever the system's default):
// transparent huge pages populate 4x faster back to back, but on a VM that hands free memory back to its host
// (Firecracker here) a fresh process's 2 MB pages are often host-faulted, and a 1024^2 preview at a user's pace
// took 242 ms against 167 (bench/history/2026-12.md, "Transparent huge pages: tried").
class PopulatedPages {
 public:
  explicit PopulatedPages(std::size_t bytes);
  PopulatedPages(PopulatedPages&& other) noexcept;
  PopulatedPages& operator=(PopulatedPages&&) = delete;
  PopulatedPages(const PopulatedPages&) = delete;
  ~PopulatedPages();
  void* data() const { return data_; }
  std::size_t size() const { return bytes_; }

 private:
  void* data_ = nullptr;
  std::size_t bytes_;
};

}  // namespace algray

// Whole-image host buffers: populated pages and huge-page vectors hold what they promise, and ask for huge pages.
#include <catch2/catch.hpp>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "large_pages.h"

using algray::assign_on_huge_pages;
using algray::PopulatedPages;

namespace {

constexpr std::size_t kHuge = std::size_t{2} << 20;

// The VmFlags line of the mapping in /proc/self/smaps that holds `address`; empty if none does.
std::string vm_flags_of(const void* address) {
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = lo <= a && a < hi;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return {};
}

bool kernel_has_thp() { return std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled"); }

}  // namespace

TEST_CASE("populated pages are zero, writable and aligned, small and large") {
  for (std::size_t bytes : {std::size_t{1}, std::size_t{4095}, std::size_t{4096}, kHuge - 1, kHuge, kHuge + 1,
                            33 * (std::size_t{1} << 20) + 12345}) {
    INFO("bytes " << bytes);
    PopulatedPages pages(bytes);
    auto* p = static_cast<unsigned char*>(pages.data());
    REQUIRE(p != nullptr);
    CHECK(reinterpret_cast<std::uintptr_t>(p) % 4096 == 0);
    if (bytes >= kHuge) CHECK(reinterpret_cast<std::uintptr_t>(p) % kHuge == 0);
    std::size_t nonzero = 0;
    for (std::size_t i = 0; i < bytes; ++i) nonzero += p[i] != 0;
    CHECK(nonzero == 0);
    p[0] = 1;
    p[bytes - 1] = 2;
    CHECK(p[bytes - 1] == 2);
    PopulatedPages moved(std::move(pages));
    CHECK(moved.data() == p);
    CHECK(pages.data() == nullptr);  // NOLINT(bugprone-use-after-move): the moved-from state is the point
  }
}

TEST_CASE("large populated pages ask the kernel for huge pages") {
  REQUIRE(kernel_has_thp());  // Debian's kernels have THP; without it this file's point cannot be checked
  PopulatedPages pages(32 * (std::size_t{1} << 20));
  const std::string flags = vm_flags_of(pages.data());
  INFO(flags);
  CHECK(flags.find(" hg") != std::string::npos);
}

TEST_CASE("assign_on_huge_pages gives n copies of the value, whatever the vector held") {
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, kHuge / 4 + 3, 9 * kHuge / 4}) {
    INFO("n " << n);
    std::vector<float> v(17, 5.0f);
    assign_on_huge_pages(v, n, 0.25f);
    REQUIRE(v.size() == n);
    std::size_t wrong = 0;
    for (float x : v) wrong += x != 0.25f;
    CHECK(wrong == 0);
    if (n * sizeof(float) >= 3 * kHuge) CHECK(vm_flags_of(v.data() + n / 2).find(" hg") != std::string::npos);
  }
  std::vector<float> big;
  assign_on_huge_pages(big, 4 * kHuge / sizeof(float), -1.0f);
  REQUIRE(kernel_has_thp());
  CHECK(vm_flags_of(big.data() + big.size() / 2).find(" hg") != std::string::npos);
}

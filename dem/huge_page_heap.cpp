#include "dem/huge_page_heap.h"

#include <cstdlib>
#include <string>

namespace magbrush::dem {

bool choose_huge_page_heap()
{
  const char *off = std::getenv("MAGBRUSH_HUGE_PAGES");
  if (off && std::string(off) == "0")
    return false; // switched off (e.g. to measure the difference)
  const char *set = std::getenv("GLIBC_TUNABLES");
  const std::string tunables = set ? set : "";
  if (tunables.find("glibc.malloc.hugetlb") != std::string::npos ||
      tunables.find("glibc.malloc.mmap_threshold") != std::string::npos)
    return false; // the user's choice wins (and a re-executed process finds its own)
  // 32 MiB: glibc's largest mmap threshold on 64-bit.
  const std::string ours = "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432";
  setenv("GLIBC_TUNABLES", (tunables.empty() ? ours : tunables + ":" + ours).c_str(), 1);
  return true;
}

std::string huge_page_heap_description()
{
  const char *set = std::getenv("GLIBC_TUNABLES");
  return std::string("GLIBC_TUNABLES=") + (set ? set : "(unset)");
}

} // namespace magbrush::dem

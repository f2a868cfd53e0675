// The engine's arrays on 2 MiB pages (transparent huge pages) instead of 4 KiB ones.
//
// Why: a step streams every particle, pair and history array once or more (~29 MB at 55k
// particles, ~40 arrays read side by side). On 4 KiB pages that is ~7,400 pages, more than the
// second-level TLB holds, so the streams keep missing the TLB, and on a virtual machine each
// miss walks two page tables (guest and host). Measured on the loaded 2-core VM
// (docs/dem_vs_lammps.md, bench_dem_packing, 5 rounds against main): the whole bench 1.30x
// faster at 14k and 1.12x at 55k (medians; min-max 1.18-1.62 and 0.92-1.52), mostly in the
// HDF5 snapshots (13-21 % of the time -> 3-5 %); the contact phase itself did not change
// measurably.
//
// How: glibc's allocator puts blocks over its mmap threshold (128 KiB, i.e. every array of a
// few thousand particles) each in its own mapping, too small for a huge page, and the kernel
// gives huge pages only where asked (the common setting "madvise"). The glibc tunables
// glibc.malloc.hugetlb=1 (advise huge pages on the heap) and glibc.malloc.mmap_threshold (keep
// blocks up to 32 MiB on that heap) do both; glibc reads them once, when the process starts,
// so the executables re-execute themselves with them set, as they do for the OpenMP settings
// (openmp_waiting.h). Nothing else changes: the same allocations, the same results.
#pragma once

#include <string>

namespace magbrush::dem {

// Unless the user set glibc.malloc.hugetlb or glibc.malloc.mmap_threshold in GLIBC_TUNABLES,
// or MAGBRUSH_HUGE_PAGES=0: appends both to GLIBC_TUNABLES. Returns true when it changed the
// environment (the caller then re-executes itself).
bool choose_huge_page_heap();

// One line for the log, e.g. "GLIBC_TUNABLES=glibc.malloc.hugetlb=1:...".
std::string huge_page_heap_description();

} // namespace magbrush::dem

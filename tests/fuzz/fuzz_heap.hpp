// SPDX-License-Identifier: MIT
#pragma once
// Heap bound for the libFuzzer targets of the file readers (fuzz_mesh_*.cpp,
// fuzz_point_file.cpp; test_fuzz_corpus.cpp holds their seeds to it in the
// test suite's ASan build): the peak of the heap a
// reader allocates for one input must stay within a fixed multiple of the
// input's size. A count in a header (PLY element counts, the STL triangle
// count) that the bytes after it cannot hold must be refused before it is
// allocated; libFuzzer's -malloc_limit_mb only sees single allocations of
// hundreds of MB, not a 4 KB input that makes a reader take 4 MB.
//
// Uses AddressSanitizer's malloc/free hooks (run.sh builds the targets with
// -fsanitize=address); in a build without ASan, or without the hooks' header
// <sanitizer/allocator_interface.h> (GCC 12 does not ship it), the bound is
// not checked.

#include <cstddef>
#include <stdexcept>
#include <string>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ICLAP_FUZZ_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) && !defined(ICLAP_FUZZ_ASAN)
#define ICLAP_FUZZ_ASAN 1
#endif
#if defined(ICLAP_FUZZ_ASAN) && defined(__has_include)
#if __has_include(<sanitizer/allocator_interface.h>)
#include <sanitizer/allocator_interface.h>
#define ICLAP_FUZZ_HEAP_HOOKS 1
#endif
#endif

namespace iclap::fuzz {

/// Bytes a reader may allocate at its peak for an input of `size` bytes:
/// 64 per input byte (a binary PLY face of uchar indices becomes int
/// triangles in a growing vector, then in the mesh; a one-byte uchar
/// coordinate becomes an 8-byte double; the seeds take at most 20) and
/// 16 KB of fixed overhead (the seeds take at most 1 KB more than 20 per
/// byte): small enough that a 4 KB input can break it.
inline std::size_t fuzz_heap_bound(std::size_t size) { return 64 * size + 16 * 1024; }

struct FuzzHeap {
  static inline std::size_t live = 0;
  static inline std::size_t peak = 0;
};

#ifdef ICLAP_FUZZ_HEAP_HOOKS
inline void fuzz_heap_on_malloc(const volatile void*, std::size_t size) {
  FuzzHeap::live += size;
  if (FuzzHeap::live > FuzzHeap::peak) FuzzHeap::peak = FuzzHeap::live;
}
inline void fuzz_heap_on_free(const volatile void* p) {
  // Blocks allocated before the hooks were installed are not counted.
  if (p && __sanitizer_get_ownership(p)) {
    const std::size_t n = __sanitizer_get_allocated_size(p);
    FuzzHeap::live -= n < FuzzHeap::live ? n : FuzzHeap::live;
  }
}
#endif

/// Measures the heap peak from construction to check(); a peak above
/// fuzz_heap_bound(size) throws std::logic_error (a crash for libFuzzer).
class FuzzHeapWatch {
 public:
  FuzzHeapWatch() {
#ifdef ICLAP_FUZZ_HEAP_HOOKS
    static const int installed = __sanitizer_install_malloc_and_free_hooks(fuzz_heap_on_malloc, fuzz_heap_on_free);
    (void)installed;
#endif
    FuzzHeap::live = 0;
    FuzzHeap::peak = 0;
  }
  void check(std::size_t size) const {
    if (FuzzHeap::peak > fuzz_heap_bound(size))
      throw std::logic_error("heap bound violated: " + std::to_string(FuzzHeap::peak) + " bytes at the peak for a " +
                             std::to_string(size) + "-byte input (bound " + std::to_string(fuzz_heap_bound(size)) +
                             ")");
  }
};

}  // namespace iclap::fuzz

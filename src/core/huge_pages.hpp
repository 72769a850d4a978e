#pragma once
// Large scratch buffers in huge pages: a map's tens of megabytes are touched
// once, and on a virtual machine a page fault per 4 kB page costs more than
// the work done in it (a third of a map's load time, a fifth of its voxel filter).
#include <cstddef>

namespace tomomap {

/// At least this many bytes come from an anonymous mapping the kernel is asked
/// (MADV_HUGEPAGE) to back with huge pages; smaller blocks from operator new.
constexpr size_t kHugePageBytes = size_t{2} << 20;

/// `bytes` of uninitialised memory; throws std::bad_alloc.
void* hugeAllocate(size_t bytes);
/// Frees what hugeAllocate(bytes) returned.
void hugeFree(void* p, size_t bytes) noexcept;

/// A std::allocator for hugeAllocate, for large scratch vectors.
template <typename T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}
  T* allocate(size_t n) { return static_cast<T*>(hugeAllocate(n * sizeof(T))); }
  void deallocate(T* p, size_t n) noexcept { hugeFree(p, n * sizeof(T)); }
  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
  template <typename U>
  bool operator!=(const HugePageAllocator<U>&) const {
    return false;
  }
};

}  // namespace tomomap

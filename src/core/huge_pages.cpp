#include "huge_pages.hpp"

#include <sys/mman.h>

#include <new>

namespace tomomap {

void* hugeAllocate(size_t bytes) {
  if (bytes < kHugePageBytes) return ::operator new(bytes);
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  ::madvise(p, bytes, MADV_HUGEPAGE);  // advice: without it, still correct memory
  return p;
}

void hugeFree(void* p, size_t bytes) noexcept {
  if (!p) return;
  if (bytes < kHugePageBytes)
    ::operator delete(p);
  else
    ::munmap(p, bytes);
}

}  // namespace tomomap

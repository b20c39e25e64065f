#include "tests/support/malloc_counter.h"

#include <cstddef>

// glibc's real allocator entry points (exported by libc.so.6).
extern "C" {
void* __libc_malloc(size_t size);
void* __libc_calloc(size_t n, size_t size);
void* __libc_realloc(void* ptr, size_t size);
void* __libc_memalign(size_t alignment, size_t size);
void __libc_free(void* ptr);
}

namespace {
// initial-exec TLS lives in the static TLS block: reading it never calls
// malloc, so the counter cannot recurse into the functions below.
__attribute__((tls_model("initial-exec"))) thread_local uint64_t g_mallocs = 0;
}  // namespace

extern "C" {

void* malloc(size_t size) {
  ++g_mallocs;
  return __libc_malloc(size);
}

void* calloc(size_t n, size_t size) {
  ++g_mallocs;
  return __libc_calloc(n, size);
}

void* realloc(void* ptr, size_t size) {
  ++g_mallocs;
  return __libc_realloc(ptr, size);
}

void* memalign(size_t alignment, size_t size) {
  ++g_mallocs;
  return __libc_memalign(alignment, size);
}

void* aligned_alloc(size_t alignment, size_t size) {
  ++g_mallocs;
  return __libc_memalign(alignment, size);
}

int posix_memalign(void** out, size_t alignment, size_t size) {
  ++g_mallocs;
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return 12;  // ENOMEM
  *out = p;
  return 0;
}

void free(void* ptr) { __libc_free(ptr); }

}  // extern "C"

namespace rover::testing {

uint64_t MallocCounter::ThreadMallocs() { return g_mallocs; }

}  // namespace rover::testing

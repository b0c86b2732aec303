/*
** memory.c — --max-memory: one budget for the Lua allocator and the
** engine's allocations together.
**
** The interpreter is linked with -Wl,--wrap for the allocation functions
** that lib/ and bindings/ call (see the Makefile), so those calls, and
** only those, reach the __wrap_ functions below, which count what they
** hand out (malloc_usable_size, so that free needs no header) and refuse
** what would go over the limit: the engine then returns OC_ENOMEM, which
** the bindings raise as a Lua error. Lua's allocator (ocrt_lua_alloc)
** shares the count and the limit, so Lua tries an emergency collection
** and then raises "not enough memory". Memory of other libraries
** (OpenImageIO, the C library's buffers, OpenMP) is not counted; lib/
** allocates through the malloc family, strdup and realpath only.
**
** OpenMP threads allocate concurrently: the counter is atomic. Memory
** freed here but allocated elsewhere (a library returning malloc'ed
** memory) can only lower the count, which loosens the limit slightly but
** never refuses a legitimate allocation.
*/
#include <errno.h>
#include <malloc.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ocrt.h"

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t n);
void __real_free(void *p);
char *__real_realpath(const char *path, char *resolved);

void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t size);
void *__wrap_realloc(void *p, size_t n);
void __wrap_free(void *p);
char *__wrap_strdup(const char *s);
char *__wrap_realpath(const char *path, char *resolved);

/* Bytes handed out and not yet freed: by the wrappers (any thread), and
** by the Lua allocator, which only the scene's thread calls, so that its
** count needs no read-modify-write (a locked add per Lua allocation cost
** 12 % on a loop making small tables). */
static atomic_llong used;
static atomic_llong lua_used;
static atomic_llong limit;   /* 0: no limit */
static atomic_int exhausted; /* an allocation was refused */

#define LOAD(x) atomic_load_explicit(&(x), memory_order_relaxed)

/* May `more` bytes be added? Sets errno and the sticky flag when not. */
static int allowed(size_t more) {
  long long lim = LOAD(limit);
  if (lim == 0) return 1;
  if (more <= (size_t)lim &&
      LOAD(used) + LOAD(lua_used) <= lim - (long long)more)
    return 1;
  atomic_store(&exhausted, 1);
  errno = ENOMEM;
  return 0;
}

static void count(void *p, long long sign) {
  if (p)
    atomic_fetch_add_explicit(&used, sign * (long long)malloc_usable_size(p),
                              memory_order_relaxed);
}

void *__wrap_malloc(size_t n) {
  void *p;
  if (!allowed(n)) return NULL;
  p = __real_malloc(n);
  count(p, 1);
  return p;
}

void *__wrap_calloc(size_t n, size_t size) {
  void *p;
  if (size != 0 && n > (size_t)-1 / size) {
    errno = ENOMEM;
    return NULL;
  }
  if (!allowed(n * size)) return NULL;
  p = __real_calloc(n, size);
  count(p, 1);
  return p;
}

void __wrap_free(void *p) {
  count(p, -1);
  __real_free(p);
}

void *__wrap_realloc(void *p, size_t n) {
  size_t old = p ? malloc_usable_size(p) : 0;
  void *q;
  if (n == 0 && p) { /* glibc's meaning, made explicit for the count */
    __wrap_free(p);
    return NULL;
  }
  if (n > old && !allowed(n - old)) return NULL;
  q = __real_realloc(p, n);
  if (q == NULL) return NULL; /* p is untouched */
  atomic_fetch_add_explicit(&used,
                            (long long)malloc_usable_size(q) - (long long)old,
                            memory_order_relaxed);
  return q;
}

char *__wrap_strdup(const char *s) {
  size_t n = strlen(s) + 1;
  char *d = __wrap_malloc(n);
  if (d) memcpy(d, s, n);
  return d;
}

char *__wrap_realpath(const char *path, char *resolved) {
  char *r = __real_realpath(path, resolved);
  if (r && resolved == NULL) count(r, 1); /* freed through __wrap_free */
  return r;
}

/* Lua gives the old size of every block, so its blocks are counted at
** the sizes it asks for, without asking malloc (this allocator is on the
** path of every table and string the scene makes). */
void *ocrt_lua_alloc(void *ud, void *p, size_t osize, size_t nsize) {
  void *q;
  (void)ud;
  if (p == NULL) osize = 0; /* then osize tells the type of the object */
  if (nsize == 0) {
    __real_free(p);
    atomic_store_explicit(&lua_used, LOAD(lua_used) - (long long)osize,
                          memory_order_relaxed);
    return NULL;
  }
  if (nsize > osize && !allowed(nsize - osize)) return NULL;
  q = __real_realloc(p, nsize);
  if (q)
    atomic_store_explicit(&lua_used,
                          LOAD(lua_used) + (long long)nsize - (long long)osize,
                          memory_order_relaxed);
  return q;
}

long long ocrt_memory_default(void) {
  long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || size <= 0) return 0;
  return (long long)pages / 2 * size;
}

void ocrt_memory_limit(long long bytes) {
  atomic_store(&limit, bytes > 0 ? bytes : 0);
  atomic_store(&exhausted, 0);
}

int ocrt_memory_exhausted(void) {
  return atomic_load(&exhausted);
}

void ocrt_memory_text(long long bytes, char *buf, size_t size) {
  static const char *const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
  int u = 0;
  while (u < 4 && bytes >= 1024 && bytes % 1024 == 0) {
    bytes /= 1024;
    u++;
  }
  snprintf(buf, size, "%lld %s", bytes, units[u]);
}

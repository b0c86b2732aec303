/*
** gen.h — the fuzzers' bytes-to-scene generator, shared by the libFuzzer
** target, the corpus replayer and scripts/fuzz-show, so that a corpus
** file always turns into the same Lua scene everywhere.
*/
#ifndef OCFZ_GEN_H
#define OCFZ_GEN_H

#include <stddef.h>
#include <stdint.h>

/* Parts of the grammar that can be left out, for runs that must pass
** while the defects they reach are fixed on other branches. */
enum {
  OCFZ_NO_CLOSE = 1, /* callbacks, finalizers and metamethods that close
                        or collect objects in use */
  OCFZ_NO_HUGE = 2   /* odd numbers in fields that size the work, and
                        heightfield.from(node), whose work is unbounded */
};

/* Reads the OCFUZZ_SKIP environment variable ("close", "huge", both
** separated by commas or spaces) into OCFZ_NO_* flags. */
int ocfz_skip_from_env(void);

/* Turns `size` bytes into a Lua scene (a NUL-terminated string, malloc'ed;
** the caller frees it) whose length goes to *len. Every byte string gives
** a syntactically valid scene; the same bytes and flags give the same
** text. Returns NULL only when out of memory. */
char *ocfz_scene(const uint8_t *data, size_t size, int flags, size_t *len);

#endif

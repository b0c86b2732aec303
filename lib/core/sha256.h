/*
** sha256.h — SHA-256 (FIPS 180-4), for provenance: the hash of a scene
** file and of every input file a run read, recorded in the metadata of
** what it wrote.
**
** Incremental: init, update any number of times with any lengths, final.
** The state is a plain struct the caller owns; nothing is allocated.
*/
#ifndef OC_SHA256_H
#define OC_SHA256_H

#include <stddef.h>
#include <stdint.h>

#define OC_SHA256_BYTES 32
#define OC_SHA256_HEX 65 /* 64 lowercase hex digits and the NUL */

typedef struct oc_sha256 {
  uint32_t h[8];
  uint64_t bytes; /* message length so far */
  unsigned char block[64];
  size_t n; /* bytes waiting in block */
} oc_sha256;

void oc_sha256_init(oc_sha256 *s);
void oc_sha256_update(oc_sha256 *s, const void *data, size_t n);
/* Writes the digest; s must be initialized again before reuse. */
void oc_sha256_final(oc_sha256 *s, unsigned char out[OC_SHA256_BYTES]);
/* The digest as lowercase hex, NUL terminated. */
void oc_sha256_hex(const unsigned char d[OC_SHA256_BYTES],
                   char hex[OC_SHA256_HEX]);
/* One call: the hex digest of n bytes. */
void oc_sha256_text(const void *data, size_t n, char hex[OC_SHA256_HEX]);

#endif

/*
** rng.h — counter-based random numbers.
**
** A value is a pure function of (seed, key, counter): streams are keyed by
** what is being generated (a sample index, a cell), never by thread or by
** scheduling order, which is what makes parallel output deterministic.
*/
#ifndef OC_RNG_H
#define OC_RNG_H

#include <stdint.h>

/* splitmix64 finalizer: a bijective 64-bit mixer with good avalanche. */
static inline uint64_t oc_mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
static inline uint64_t oc_hash2(uint64_t a, uint64_t b) {
  return oc_mix64(a ^ oc_mix64(b + 0x632be59bd9b4e019ull));
}

typedef struct oc_rng {
  uint64_t key;     /* derived from seed and stream key */
  uint64_t counter; /* advances by one per draw */
} oc_rng;

/* The stream for `key` under `seed`; independent streams for distinct keys. */
static inline oc_rng oc_rng_stream(uint64_t seed, uint64_t key) {
  oc_rng r = {oc_hash2(seed, key), 0};
  return r;
}
/* A child stream, for splitting work hierarchically. */
static inline oc_rng oc_rng_split(const oc_rng *r, uint64_t key) {
  oc_rng c = {oc_hash2(r->key, key ^ 0x5851f42d4c957f2dull), 0};
  return c;
}
static inline uint64_t oc_rng_next(oc_rng *r) {
  return oc_mix64(r->key ^ oc_mix64(r->counter++));
}
/* Uniform in [0, 1) with 53 random bits. */
static inline double oc_rng_uniform(oc_rng *r) {
  return (double)(oc_rng_next(r) >> 11) * 0x1.0p-53;
}
static inline double oc_rng_range(oc_rng *r, double lo, double hi) {
  return lo + (hi - lo) * oc_rng_uniform(r);
}

#endif

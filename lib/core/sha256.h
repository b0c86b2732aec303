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

/* The declarations are public: outcrop.h holds them. */
#include "outcrop.h"

#endif

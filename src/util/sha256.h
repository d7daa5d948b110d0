/* SHA-256 (FIPS 180-4), for the content checks of the files a scene file names. */
#ifndef DWV_UTIL_SHA256_H
#define DWV_UTIL_SHA256_H

#include <stddef.h>
#include <stdint.h>

typedef struct dwvu_sha256 {
    uint32_t state[8];
    uint64_t length;       /* bytes hashed so far */
    unsigned char block[64];
    size_t used;           /* bytes waiting in block */
} dwvu_sha256;

void dwvu_sha256_init(dwvu_sha256 *h);
void dwvu_sha256_add(dwvu_sha256 *h, const void *data, size_t size);
/* The digest as 64 lower-case hexadecimal digits and a NUL. */
void dwvu_sha256_hex(dwvu_sha256 *h, char hex[65]);

#endif

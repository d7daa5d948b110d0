/* SHA-256 (src/util/sha256.c) against FIPS 180-4's examples (NIST's "SHA256.pdf" example values:
 * "abc", the 448-bit message, a million 'a') and the empty message, fed whole and in uneven
 * pieces (blocks split across calls, the padding's 56-byte boundary). */
#include <string.h>

#include "check.h"
#include "util/sha256.h"

static void digest(const char *what, const unsigned char *data, size_t size, size_t piece, const char *want)
{
    dwvu_sha256 h;
    dwvu_sha256_init(&h);
    for (size_t at = 0; at < size; at += piece) dwvu_sha256_add(&h, data + at, size - at < piece ? size - at : piece);
    char hex[65];
    dwvu_sha256_hex(&h, hex);
    CHECK(strcmp(hex, want) == 0, "%s (pieces of %zu): %s, want %s", what, piece, hex, want);
}

int main(void)
{
    static unsigned char million[1000000];
    memset(million, 'a', sizeof million);
    const char *two_blocks = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
    size_t pieces[] = {1, 7, 64, 1000000};
    for (size_t k = 0; k < 4; ++k) {
        digest("empty", (const unsigned char *)"", 0, pieces[k],
               "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
        digest("abc", (const unsigned char *)"abc", 3, pieces[k],
               "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
        digest("448 bits", (const unsigned char *)two_blocks, strlen(two_blocks), pieces[k],
               "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
        if (pieces[k] > 1)
            digest("a million a", million, sizeof million, pieces[k],
                   "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
    }
    return check_report("test_sha256");
}

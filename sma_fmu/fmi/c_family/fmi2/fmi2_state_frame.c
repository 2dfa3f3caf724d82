/* The frame around a serialized state, the same in both families (the pythonfmu FMUs' front
 * writes it in fmi/native/state_bytes.c): a 20-byte header, then the body.
 *   "SMAF" | u32 frame version (1) | u64 body length | u32 CRC-32 of the body | body
 * (native byte order). CRC-32 is zlib's (polynomial 0xEDB88320): it detects every change of
 * up to 32 consecutive bits, so any one changed byte, and a truncated or extended body
 * (the length field), is refused before a single entry of the body is read. */
#include "fp_contract.h"
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "fmi2_layer.h"

static const char FRAME_MAGIC[4] = {'S', 'M', 'A', 'F'};
static const uint32_t FRAME_VERSION = 1u;

uint32_t layer_crc32(const unsigned char *data, size_t n)
{
    uint32_t crc = 0xFFFFFFFFu;
    size_t i;
    int k;
    for (i = 0; i < n; ++i) {
        crc ^= data[i];
        for (k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

void layer_frame_write(unsigned char *bytes, size_t body_size)
{
    uint64_t length = body_size;
    uint32_t crc = layer_crc32(bytes + STATE_FRAME_SIZE, body_size);
    memcpy(bytes, FRAME_MAGIC, 4);
    memcpy(bytes + 4, &FRAME_VERSION, 4);
    memcpy(bytes + 8, &length, 8);
    memcpy(bytes + 16, &crc, 4);
}

int layer_frame_check(const unsigned char *bytes, size_t size, char *why, size_t why_size)
{
    uint32_t version, stored, computed;
    uint64_t length;
    if (size < STATE_FRAME_SIZE) {
        snprintf(why, why_size, "%lu bytes are shorter than the %d-byte header",
                 (unsigned long)size, STATE_FRAME_SIZE);
        return 0;
    }
    if (memcmp(bytes, FRAME_MAGIC, 4) != 0) {
        snprintf(why, why_size, "the header does not start with SMAF: not a state of an sma-fmu FMU");
        return 0;
    }
    memcpy(&version, bytes + 4, 4);
    memcpy(&length, bytes + 8, 8);
    memcpy(&stored, bytes + 16, 4);
    if (version != FRAME_VERSION) {
        snprintf(why, why_size, "header version %lu, this FMU reads version %lu",
                 (unsigned long)version, (unsigned long)FRAME_VERSION);
        return 0;
    }
    if (length != (uint64_t)(size - STATE_FRAME_SIZE)) {
        snprintf(why, why_size, "the header's length field says %llu body bytes, %lu follow it "
                 "(truncated, extended or a corrupt length)", (unsigned long long)length,
                 (unsigned long)(size - STATE_FRAME_SIZE));
        return 0;
    }
    computed = layer_crc32(bytes + STATE_FRAME_SIZE, size - STATE_FRAME_SIZE);
    if (computed != stored) {
        snprintf(why, why_size, "the checksum does not match (CRC-32 0x%08lx in the header, "
                 "0x%08lx of the body): the bytes were changed", (unsigned long)stored,
                 (unsigned long)computed);
        return 0;
    }
    return 1;
}

/*
 * state_bytes.c - the header the front puts before pythonfmu's serialized state:
 * magic "SMAF", version (u32), payload length (u64), CRC-32 of the payload (u32).
 * Bytes that are not such a state (truncated, corrupted, from another FMU type) give
 * fmi2Error at fmi2DeSerializeFMUstate, naming what failed, instead of reaching Python.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "front.h"

static const char magic[4] = {'S', 'M', 'A', 'F'};
static const uint32_t version = 1;

static uint32_t crc32(const unsigned char* data, size_t n)
{
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; ++i) {
        crc ^= data[i];
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

void write_state_header(fmi2Byte* bytes, size_t payload_size)
{
    uint64_t length = payload_size;
    uint32_t crc = crc32((const unsigned char*)bytes + STATE_HEADER_SIZE, payload_size);
    memcpy(bytes, magic, 4);
    memcpy(bytes + 4, &version, 4);
    memcpy(bytes + 8, &length, 8);
    memcpy(bytes + 16, &crc, 4);
}

/* The same checks and texts as the C family's (c_family/fmi2/fmi2_state_frame.c). */
int state_header_check(const fmi2Byte* bytes, size_t size, char* why, size_t why_size)
{
    uint32_t stored_version, stored, computed;
    uint64_t length;
    if (size < STATE_HEADER_SIZE) {
        snprintf(why, why_size, "%zu bytes are shorter than the %d-byte header", size,
                 STATE_HEADER_SIZE);
        return 0;
    }
    if (memcmp(bytes, magic, 4) != 0) {
        snprintf(why, why_size, "the header does not start with SMAF: not a state of an sma-fmu FMU");
        return 0;
    }
    memcpy(&stored_version, bytes + 4, 4);
    memcpy(&length, bytes + 8, 8);
    memcpy(&stored, bytes + 16, 4);
    if (stored_version != version) {
        snprintf(why, why_size, "header version %lu, this FMU reads version %lu",
                 (unsigned long)stored_version, (unsigned long)version);
        return 0;
    }
    if (length != (uint64_t)(size - STATE_HEADER_SIZE)) {
        snprintf(why, why_size, "the header's length field says %llu body bytes, %zu follow it "
                 "(truncated, extended or a corrupt length)", (unsigned long long)length,
                 size - STATE_HEADER_SIZE);
        return 0;
    }
    computed = crc32((const unsigned char*)bytes + STATE_HEADER_SIZE, size - STATE_HEADER_SIZE);
    if (computed != stored) {
        snprintf(why, why_size, "the checksum does not match (CRC-32 0x%08lx in the header, "
                 "0x%08lx of the body): the bytes were changed", (unsigned long)stored,
                 (unsigned long)computed);
        return 0;
    }
    return 1;
}

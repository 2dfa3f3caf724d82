/*
 * state_bytes.c - the header the front puts before pythonfmu's serialized state:
 * magic "SMAF", version (u32), payload length (u64), CRC-32 of the payload (u32).
 * Bytes that are not such a state (truncated, corrupted, from another FMU type) give
 * fmi2Error at fmi2DeSerializeFMUstate instead of reaching Python.
 */
#include <stdint.h>
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

int state_header_valid(const fmi2Byte* bytes, size_t size)
{
    if (size < STATE_HEADER_SIZE || memcmp(bytes, magic, 4) != 0) return 0;
    uint32_t stored_version, crc;
    uint64_t length;
    memcpy(&stored_version, bytes + 4, 4);
    memcpy(&length, bytes + 8, 8);
    memcpy(&crc, bytes + 16, 4);
    return stored_version == version && length == size - STATE_HEADER_SIZE &&
           crc == crc32((const unsigned char*)bytes + STATE_HEADER_SIZE, size - STATE_HEADER_SIZE);
}

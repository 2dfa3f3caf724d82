/* The frame around a serialized state, the same in both families: a 20-byte header, then
 * the body.
 *   "SMAF" | u32 frame version (1) | u64 body length | u32 CRC-32 of the body | body
 * (native byte order). CRC-32 is zlib's (polynomial 0xEDB88320): it detects every change of
 * up to 32 consecutive bits, so any one changed byte, and a truncated or extended body (the
 * length field), is refused before a single byte of the body is read. The C family frames
 * its binary state (c_family/core/layer_state_bytes.c), the Python family's front pythonfmu's
 * (front/fmi2_states.c). */
#ifndef SMA_STATE_FRAME_H
#define SMA_STATE_FRAME_H

#include <stddef.h>

#define STATE_FRAME_SIZE 20

/* Write the header into bytes[0..STATE_FRAME_SIZE) for the body_size bytes that follow it. */
void state_frame_write(unsigned char *bytes, size_t body_size);
/* 1 if bytes[0..size) is a frame whose header matches its body; else 0 with `why` naming
 * what failed (too short, magic, version, length, checksum). */
int state_frame_check(const unsigned char *bytes, size_t size, char *why, size_t why_size);

#endif

/* resources/start_values.json read safely, with the checks and messages of the pythonfmu
 * family's reader (python_family/slave_support/start_values.py), in the same order:
 *   a regular file only (opened without blocking: a FIFO, a folder, a device is refused at
 *   once), at most START_FILE_MAX_BYTES, no NUL byte, strict UTF-8 (no encoded surrogates,
 *   which Python's decoder refuses), nested at most START_FILE_MAX_DEPTH deep.
 * The JSON itself is then read by json_text.c, as json.loads reads it. */
#ifndef _WIN32
#define _POSIX_C_SOURCE 200809L  /* open, fstat, O_NONBLOCK */
#endif
#include "fp_contract.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "layer.h"
#include "json_string.h"
#include "json_text.h"

#ifdef _WIN32
#define IS_REGULAR(mode) (((mode) & _S_IFMT) == _S_IFREG)
#else
#include <fcntl.h>
#include <unistd.h>
#define IS_REGULAR(mode) S_ISREG(mode)
#endif

#define START_FILE_MAX_BYTES JSON_TEXT_MAX_BYTES
#define START_FILE_MAX_DEPTH JSON_TEXT_MAX_DEPTH
#define START_FILE_NAME "start_values.json"

/* All of `stream` in a malloc'd, NUL-terminated buffer, at most START_FILE_MAX_BYTES + 1
 * bytes of it (more is refused by the caller); NULL when out of memory. */
static char *read_all(FILE *stream, size_t *used)
{
    size_t room = 4096;
    char *text = (char *)malloc(room);
    *used = 0;
    while (text && *used <= START_FILE_MAX_BYTES) {
        size_t n = fread(text + *used, 1, room - *used - 1, stream);
        char *grown;
        *used += n;
        if (n == 0) break;
        if (room - *used - 1 > 0) continue;
        grown = (char *)realloc(text, room * 2);
        if (!grown) { free(text); return NULL; }
        text = grown;
        room *= 2;
    }
    if (text) text[*used] = '\0';
    return text;
}

/* The bytes of the open `stream` of the file at `path` whose type is in `info`, or NULL with
 * why (not a regular file, too large, out of memory). Closes the stream. */
static char *checked_bytes(FILE *stream, const struct stat *info, const char *path, size_t *used,
                           char *why, size_t size)
{
    char *text = NULL;
    int too_large = 0;
    if (!IS_REGULAR(info->st_mode)) {
        snprintf(why, size, "%.300s: cannot be read (not a regular file)", path);
    } else if ((unsigned long long)info->st_size > START_FILE_MAX_BYTES) {
        too_large = 1;
    } else if (!(text = read_all(stream, used))) {
        snprintf(why, size, "%.300s: cannot be read (out of memory)", path);
    } else if (*used > START_FILE_MAX_BYTES) {  /* it grew while it was read */
        free(text);
        text = NULL;
        too_large = 1;
    }
    fclose(stream);
    if (too_large)
        snprintf(why, size, "%.300s: cannot be read (larger than %d bytes, the limit for %s)",
                 path, START_FILE_MAX_BYTES, START_FILE_NAME);
    return text;
}

/* The file's bytes (malloc'd, NUL-terminated), or NULL: *missing = 1 when there is none.
 * POSIX: opened without blocking, then its type is read from the descriptor (a FIFO is
 * refused, never read). Windows: its type is read first (a folder cannot be opened). */
static char *file_bytes(const char *path, size_t *used, int *missing, char *why, size_t size)
{
    struct stat info;
    FILE *stream = NULL;
#ifdef _WIN32
    int failed = stat(path, &info) != 0;
    if (!failed && !IS_REGULAR(info.st_mode)) {
        *missing = 0;
        snprintf(why, size, "%.300s: cannot be read (not a regular file)", path);
        return NULL;
    }
    failed = failed || !(stream = fopen(path, "rb"));
#else
    int fd = open(path, O_RDONLY | O_NONBLOCK);
    int failed = fd < 0;
    if (!failed && (fstat(fd, &info) != 0 || !(stream = fdopen(fd, "rb")))) {
        close(fd);
        failed = 1;
    }
#endif
    *missing = failed && errno == ENOENT;
    if (failed) {
        if (!*missing) snprintf(why, size, "%.300s: cannot be read (%s)", path, strerror(errno));
        return NULL;
    }
    return checked_bytes(stream, &info, path, used, why, size);
}

/* The first byte that is not strict UTF-8 (an encoded surrogate ED A0..BF counts), or n. */
static size_t strict_utf8_end(const unsigned char *text, size_t n)
{
    size_t valid = json_valid_utf8(text, n), i;
    for (i = 0; i + 1 < valid; ++i)  /* in valid UTF-8, 0xED is always a lead byte */
        if (text[i] == 0xED && text[i + 1] >= 0xA0) return i;
    return valid;
}

/* Does the nesting of brackets outside strings exceed the limit? As start_values.py counts:
 * a string runs to its closing quote (a backslash escapes the next byte) or to the end. */
static int too_deep(const char *text, size_t n)
{
    size_t i;
    long depth = 0;
    for (i = 0; i < n; ++i) {
        char c = text[i];
        if (c == '"') {
            for (++i; i < n && text[i] != '"'; ++i)
                if (text[i] == '\\') ++i;
        } else if (c == '[' || c == '{') {
            if (++depth > START_FILE_MAX_DEPTH) return 1;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return 0;
}

char *layer_start_file(const char *path, int *missing, char *why, size_t size)
{
    size_t used, bad;
    const char *nul;
    char *text = file_bytes(path, &used, missing, why, size);
    if (!text) return NULL;
    nul = (const char *)memchr(text, '\0', used);
    bad = strict_utf8_end((const unsigned char *)text, used);
    if (nul)
        snprintf(why, size, "%.300s: cannot be read (a NUL byte at byte %lu)", path,
                 (unsigned long)(nul - text));
    else if (bad != used)
        snprintf(why, size, "%.300s: cannot be read (invalid UTF-8 at byte %lu)", path,
                 (unsigned long)bad);
    else if (too_deep(text, used))
        snprintf(why, size, "%.300s: cannot be read (nesting deeper than %d levels, the limit "
                 "for %s)", path, START_FILE_MAX_DEPTH, START_FILE_NAME);
    else
        return text;
    free(text);
    return NULL;
}

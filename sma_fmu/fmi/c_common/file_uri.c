/* fmuResourceLocation -> a local folder path (file_uri.h). */
#include "file_uri.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int same_text(const char *a, const char *b, size_t n)  /* ASCII, ignoring case */
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (tolower((unsigned char)a[i]) != tolower((unsigned char)b[i])) return 0;
    return 1;
}

#ifdef _WIN32
static int drive_path(const char *path)  /* "C:/" or "C:\" */
{
    return isalpha((unsigned char)path[0]) && path[1] == ':' && (path[2] == '/' || path[2] == '\\');
}
#endif

static int hex_value(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* The path part of `uri` (after the scheme and an empty or "localhost" authority) and its
 * length, or NULL with why set. */
static const char *uri_path(const char *uri, size_t *length, int *plain, char *why, size_t size)
{
    const char *p;
#ifdef _WIN32
    *plain = drive_path(uri);
#else
    *plain = uri[0] == '/';
#endif
    if (*plain) {  /* a plain absolute path, not a URI: pythonfmu took it, so do we */
        *length = strlen(uri);
        return uri;
    }
    if (!same_text(uri, "file:", 5)) {
        snprintf(why, size, "fmuResourceLocation '%.300s' is not a file: URI", uri);
        return NULL;
    }
    p = uri + 5;
    if (p[0] == '/' && p[1] == '/') {  /* an authority: empty or localhost */
        const char *host = p + 2, *end = strchr(host, '/');
        size_t n = end ? (size_t)(end - host) : strlen(host);
        if (n != 0 && !(n == 9 && same_text(host, "localhost", 9))) {
            snprintf(why, size, "fmuResourceLocation '%.300s' names host '%.*s'; only local "
                     "files are supported", uri, (int)(n > 100 ? 100 : n), host);
            return NULL;
        }
        if (!end) {
            snprintf(why, size, "fmuResourceLocation '%.300s' has no path", uri);
            return NULL;
        }
        p = end;
    }
    if (*p != '/') {
        snprintf(why, size, "fmuResourceLocation '%.300s' is not an absolute path", uri);
        return NULL;
    }
#ifdef _WIN32
    if (!drive_path(p + 1)) {
        snprintf(why, size, "fmuResourceLocation '%.300s' does not name a drive (file:///C:/...)", uri);
        return NULL;
    }
    ++p;  /* "/C:/dir" is the drive path "C:/dir" */
#endif
    *length = strcspn(p, "?#");  /* query and fragment are not part of the path */
    return p;
}

char *file_uri_folder(const char *uri, int *plain, char *why, size_t size)
{
    size_t length = 0, i, j = 0;
    const char *path = uri_path(uri, &length, plain, why, size);
    char *out;
    if (!path) return NULL;
    out = (char *)malloc(length + 1);
    if (!out) { snprintf(why, size, "out of memory"); return NULL; }
    for (i = 0; i < length; ++i) {
        if (path[i] == '%' && !*plain) {
            int high = i + 2 < length ? hex_value(path[i + 1]) : -1;
            int low = i + 2 < length ? hex_value(path[i + 2]) : -1;
            if (high < 0 || low < 0 || (high == 0 && low == 0)) {
                free(out);
                snprintf(why, size, "fmuResourceLocation '%.300s' has a bad percent escape", uri);
                return NULL;
            }
            out[j++] = (char)(high * 16 + low);
            i += 2;
        } else {
            out[j++] = path[i];
        }
    }
    out[j] = '\0';
    while (j > 1 && (out[j - 1] == '/' || out[j - 1] == '\\')) out[--j] = '\0';
    return out;
}

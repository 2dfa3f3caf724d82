/* fmuResourceLocation -> the resources folder: the URI is read as the Python family's front
 * reads it (both compile fmi/c_common/file_uri.c: file:///abs, file:/abs, file://localhost/abs,
 * percent-decoded, and with a warning a plain absolute path); here the folder must exist and
 * hold the FMU's parameters.json (the front asks for pythonfmu's slavemodule.txt instead). */
#ifndef _WIN32
#define _POSIX_C_SOURCE 200809L  /* stat() */
#endif
#include "fp_contract.h"
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "file_uri.h"
#include "layer.h"

#ifdef _WIN32
#define IS_FOLDER(mode) (((mode) & _S_IFMT) == _S_IFDIR)
#define IS_REGULAR(mode) (((mode) & _S_IFMT) == _S_IFREG)
#else
#define IS_FOLDER(mode) S_ISDIR(mode)
#define IS_REGULAR(mode) S_ISREG(mode)
#endif

/* Is `folder` an unpacked FMU's resources folder? Every FMU of this project ships
 * parameters.json there (the pythonfmu family's front asks for its slave module), so a
 * location such as file:///tmp is refused instead of silently running without the FMU's
 * files (its packed start_values.json among them). */
static int owns_folder(const char *folder, const char *uri, char *why, size_t size)
{
    struct stat info;
    char path[4200];
    snprintf(path, sizeof path, "%s/parameters.json", folder);
    if (stat(path, &info) == 0 && IS_REGULAR(info.st_mode)) return 1;
    snprintf(why, size, "resource folder '%.300s' (from fmuResourceLocation '%.300s') is not this "
             "FMU's resources folder: it holds no parameters.json", folder, uri);
    return 0;
}

int layer_resource_folder(const char *uri, char **folder, int *plain, char *why, size_t size)
{
    char *out;
    struct stat info;
    if (!uri) { snprintf(why, size, "fmuResourceLocation is NULL"); return 0; }
    if (!*uri) { snprintf(why, size, "fmuResourceLocation is empty"); return 0; }
    if (!layer_valid_utf8(uri)) { snprintf(why, size, "fmuResourceLocation is not UTF-8"); return 0; }
    out = file_uri_folder(uri, plain, why, size);
    if (!out) return 0;
    if (!layer_valid_utf8(out) || stat(out, &info) != 0 || !IS_FOLDER(info.st_mode)) {
        snprintf(why, size, "resource folder '%.300s' (from fmuResourceLocation '%.300s') does not "
                 "exist", out, uri);
        free(out);
        return 0;
    }
    if (!owns_folder(out, uri, why, size)) {
        free(out);
        return 0;
    }
    *folder = out;
    return 1;
}

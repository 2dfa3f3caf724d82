/* fmuResourceLocation -> a local folder path, for both families of FMUs (the C family's
 * c_family/core/layer_resources.c and the Python family's front/resource_uri.c compile this file).
 * Each family then checks the folder its own way. */
#ifndef SMA_FILE_URI_H
#define SMA_FILE_URI_H

#include <stddef.h>

/* The folder `uri` names, malloc'd and percent-decoded, without trailing separators; NULL
 * with `why` (which quotes the URI, at most 300 bytes of it) when it is not a local file:
 * URI. Taken: file:///abs, file:/abs and file://localhost/abs, query and fragment dropped,
 * and a plain absolute path (then *plain = 1 and nothing is decoded). On Windows the path is
 * a drive path (file:///C:/dir, or plain C:\dir). `uri` must be a non-empty string; the
 * caller checks NULL, "" and UTF-8, and whether the folder exists. */
char *file_uri_folder(const char *uri, int *plain, char *why, size_t size);

#endif

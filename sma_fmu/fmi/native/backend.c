/*
 * backend.c - loading pythonfmu's binary, <modelIdentifier>_pythonfmu.so, found beside
 * the front itself (dladdr). Done once per process, at the first fmi2Instantiate.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"

Backend backend;
char load_error[sizeof load_error] = ""; /* sizes: front.h */
char load_info[sizeof load_info] = "";

static pthread_mutex_t load_mutex = PTHREAD_MUTEX_INITIALIZER;
static int load_state = 0; /* 0 not tried, 1 loaded, -1 failed */

/*
 * pythonfmu 0.7.0 releases its PyState twice at process exit: the destructor of its static
 * std::shared_ptr runs among the exit handlers, then its library destructor
 * (onLibraryUnload) assigns nullptr to that destroyed shared_ptr and releases the freed
 * block again (valgrind: invalid read in finalizePythonInterpreter; now and then glibc
 * aborts with "corrupted double-linked list"). Exit handlers run last-registered first, so
 * this one, registered after pythonfmu's binary is loaded, runs before pythonfmu's static
 * destructor: it empties the shared_ptr through pythonfmu's own finalizePythonInterpreter,
 * and both later steps then find it empty.
 */
static void (*finalize_python)(void);

static void finalize_backend_at_exit(void)
{
    if (finalize_python) finalize_python();
}

/* <directory of this library>/<its name without .so>_pythonfmu.so into path, or 0. */
static int backend_path(char* path, size_t size)
{
    Dl_info self;
    if (!dladdr((void*)&backend_path, &self) || !self.dli_fname) {
        snprintf(load_error, sizeof load_error, "cannot locate the front library itself (dladdr)");
        return 0;
    }
    snprintf(path, size, "%s", self.dli_fname);
    char* dot = strrchr(path, '.');
    char* slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash) || strcmp(dot, ".so") != 0 ||
        strlen(path) + sizeof "_pythonfmu.so" > size) {
        snprintf(load_error, sizeof load_error, "front library %s is not named <modelIdentifier>.so",
                 self.dli_fname);
        return 0;
    }
    strcpy(dot, "_pythonfmu.so");
    return 1;
}

int load_backend(void)
{
    pthread_mutex_lock(&load_mutex);
    if (load_state == 0) {
        load_state = -1;
        char path[PATH_MAX];
        void* handle = NULL;
        if (!backend_path(path, sizeof path) || !ensure_libpython()) goto done;
        if (!resolve_python_api()) {
            snprintf(load_error, sizeof load_error, "the Python in this process lacks the GIL API");
            goto done;
        }
        dlerror();
        handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            snprintf(load_error, sizeof load_error, "cannot load pythonfmu's binary: %s", dlerror());
            goto done;
        }
#define LOOKUP(ret, name, args)                                                                  \
        if (!(*(void**)(&backend.name) = dlsym(handle, "fmi2" #name))) {                         \
            snprintf(load_error, sizeof load_error, "%s lacks fmi2" #name, path);                \
            goto done;                                                                           \
        }
        BACKEND_FUNCTIONS(LOOKUP)
#undef LOOKUP
        *(void**)(&finalize_python) = dlsym(handle, "finalizePythonInterpreter");
        if (finalize_python) atexit(finalize_backend_at_exit);
        load_state = 1;
    }
done:;
    int loaded = load_state == 1;
    pthread_mutex_unlock(&load_mutex);
    return loaded;
}

/*
 * backend.c - pythonfmu's binary, <modelIdentifier>_pythonfmu.so / .dll, found beside the
 * front itself, and the Python it runs in. Done once per copy of the front, at its first
 * fmi2Instantiate: either this copy becomes the owner (loads Python and the backend, and
 * stays loaded until the process ends), or it shares an owner's (see FrontShare, front.h).
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"

Backend backend;
char load_error[sizeof load_error] = ""; /* sizes: front.h */
char load_info[sizeof load_info] = "";

static Mutex load_mutex = MUTEX_INITIALIZER;
static int load_state = 0; /* 0 not tried, 1 loaded, -1 failed */
static RuntimeCalls calls;

/* What an owner offers other copies of the front (found by name, see share_posix.c). */
EXPORT FrontShare sma_fmu_front_share;

void keep_thread_state(void)
{
    if (calls.keep_thread_state) calls.keep_thread_state();
}

fmi2Component instantiate_backend(fmi2String name, fmi2Type type, fmi2String guid, fmi2String uri,
                                  const fmi2CallbackFunctions* cb, fmi2Boolean visible)
{
    return calls.instantiate(name, type, guid, uri, cb, visible);
}

void forget_resources(const char* folder)
{
    if (calls.forget_resources) calls.forget_resources(folder);
}

int can_call_step(void) { return calls.call_step != NULL; }

int call_step(void* callable, void* queue, long* queued, const StepCall* call)
{
    *queued = 1;
    return calls.call_step ? calls.call_step(callable, queue, queued, call) : -1;
}

#ifndef _WIN32
/*
 * pythonfmu 0.7.0 releases its PyState twice at process exit: the destructor of its static
 * std::shared_ptr runs among the exit handlers, then its library destructor
 * (onLibraryUnload) assigns nullptr to that destroyed shared_ptr and releases the freed
 * block again (valgrind: invalid read in finalizePythonInterpreter; now and then glibc
 * aborts with "corrupted double-linked list"). Exit handlers run last-registered first, so
 * this one, registered (by the owner, which is never unloaded) after pythonfmu's binary is
 * loaded, runs before pythonfmu's static destructor: it empties the shared_ptr through
 * pythonfmu's own finalizePythonInterpreter, and both later steps then find it empty.
 */
static void (*finalize_python)(void);

static void finalize_backend_at_exit(void)
{
    if (finalize_python) finalize_python();
}
#endif

/* <this library without its suffix>_pythonfmu<suffix> into path, or 0. */
static int backend_path(char* path, size_t size)
{
    if (!self_path(path, size)) {
        snprintf(load_error, sizeof load_error, "cannot locate the front library itself");
        return 0;
    }
    size_t n = strlen(path), suffix = strlen(LIBRARY_SUFFIX);
    if (n <= suffix || strcmp(path + n - suffix, LIBRARY_SUFFIX) != 0 ||
        n + sizeof "_pythonfmu" > size) {
        snprintf(load_error, sizeof load_error, "front library %.1500s is not named <modelIdentifier>%s",
                 path, LIBRARY_SUFFIX);
        return 0;
    }
    snprintf(path + n - suffix, size - (n - suffix), "_pythonfmu%s", LIBRARY_SUFFIX);
    return 1;
}

/* Take an owner's backend and runtime calls. */
static void share(const FrontShare* owner)
{
    backend = owner->backend;
    calls = owner->calls;
    snprintf(load_info, sizeof load_info, "%.500s, shared with the copy of the front at %.450s",
             owner->python, owner->owner);
}

/* Load Python and the backend, and offer them to later copies. 1 on success. */
static int own(const char* path, const unsigned char* id, size_t id_size)
{
    if (!load_libpython()) return 0;
    if (!start_python_runtime(&calls)) {
        snprintf(load_error, sizeof load_error, "the Python in this process lacks the GIL API "
                 "(%.1000s)", load_info);
        return 0;
    }
    char reason[1024];
    Library handle = library_open(path, 0, 1, reason, sizeof reason);
    if (!handle) {
        snprintf(load_error, sizeof load_error, "cannot load pythonfmu's binary %.900s: %.900s", path, reason);
        return 0;
    }
#define LOOKUP(ret, name, args)                                                                  \
    if (!(*(void**)(&backend.name) = library_symbol(handle, "fmi2" #name))) {                    \
        snprintf(load_error, sizeof load_error, "%.1500s lacks fmi2" #name, path);                    \
        return 0;                                                                                \
    }
    BACKEND_FUNCTIONS(LOOKUP)
#undef LOOKUP
    pin_self(); /* Python's thread states, exit handler and other copies rely on this copy */
#ifndef _WIN32
    *(void**)(&finalize_python) = library_symbol(handle, "finalizePythonInterpreter");
    if (finalize_python) atexit(finalize_backend_at_exit);
#endif
    if (id_size) {
        FrontShare* offer = &sma_fmu_front_share;
        memcpy(offer->magic, SHARE_MAGIC, sizeof offer->magic);
        offer->abi = SHARE_ABI;
        memcpy(offer->backend_id, id, id_size);
        offer->backend_id_size = id_size;
        offer->backend = backend;
        offer->calls = calls;
        snprintf(offer->python, sizeof offer->python, "%s", load_info);
        if (!self_path(offer->owner, sizeof offer->owner)) snprintf(offer->owner, sizeof offer->owner, "?");
        __atomic_store_n(&offer->ready, 1, __ATOMIC_RELEASE);
    }
    return 1;
}

int load_backend(void)
{
    mutex_lock(&load_mutex);
    if (load_state == 0) {
        load_state = -1;
        char path[PATH_SIZE];
        unsigned char id[64];
        size_t id_size = 0;
        if (backend_path(path, sizeof path)) {
            if (!backend_build_id(path, id, &id_size)) id_size = 0;
            const FrontShare* owner = id_size ? find_owner(id, id_size) : NULL;
            if (owner) {
                share(owner);
                load_state = 1;
            } else if (own(path, id, id_size)) {
                load_state = 1;
            }
        }
    }
    int loaded = load_state == 1;
    mutex_unlock(&load_mutex);
    return loaded;
}

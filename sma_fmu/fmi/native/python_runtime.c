/*
 * python_runtime.c - the Python the backend runs in.
 *
 * pythonfmu's binary does not link libpython: it expects the Python C API in the global
 * symbol scope. A Python host (fmpy, libcosimpy, ecospy) has it already, and a second
 * libpython must never be loaded into such a process. A C host has none: then the front
 * loads one with RTLD_GLOBAL, trying $SMA_FMU_LIBPYTHON, the library of the Python that
 * built the FMU (SMA_FRONT_LIBPYTHON, recorded at build time), its soname and Debian's path.
 *
 * pythonfmu takes the GIL with PyGILState_Ensure/Release around every call. In a thread
 * Python does not know, that creates and deletes a Python thread state per call (an mmap
 * and munmap each time). keep_thread_state() creates one per host thread on its first call
 * and parks it, so pythonfmu's calls reuse it; it is released when the thread exits.
 * SMA_FMU_NO_TSTATE=1 switches this off (for measurements).
 *
 * No Python header is needed: the few C-API functions used are looked up with dlsym.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <link.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <unistd.h>

#include "front.h"

#ifndef SMA_FRONT_LIBPYTHON
#define SMA_FRONT_LIBPYTHON "" /* absolute path of the build's libpython */
#endif
#ifndef SMA_FRONT_LIBPYTHON_SONAME
#define SMA_FRONT_LIBPYTHON_SONAME "libpython3.so"
#endif
#define DEBIAN_LIBPYTHON "/usr/lib/x86_64-linux-gnu/" SMA_FRONT_LIBPYTHON_SONAME

int use_thread_state_keeper = 1;

static struct {
    int (*IsInitialized)(void);
    int (*GILState_Ensure)(void); /* PyGILState_STATE is an int-sized enum */
    void* (*GILState_GetThisThreadState)(void);
    void* (*Eval_SaveThread)(void);
    void (*Eval_RestoreThread)(void*);
    int (*IsFinalizing)(void); /* Py_IsFinalizing (3.13+) or _Py_IsFinalizing; may be NULL */
    void (*ThreadState_Clear)(void*);
    void (*ThreadState_DeleteCurrent)(void);
} py;

static pthread_key_t kept_state_key;

static void append(char* text, size_t size, const char* format, ...)
    __attribute__((format(printf, 3, 4)));
static void append(char* text, size_t size, const char* format, ...)
{
    size_t used = strlen(text);
    if (used + 1 >= size) return;
    va_list args;
    va_start(args, format);
    vsnprintf(text + used, size - used, format, args);
    va_end(args);
}

/* dl_iterate_phdr callback: the first mapped libpython3*, if any. */
static int find_mapped_libpython(struct dl_phdr_info* info, size_t size, void* found)
{
    (void)size;
    const char* name = info->dlpi_name;
    const char* base = name ? strrchr(name, '/') : NULL;
    base = base ? base + 1 : name;
    if (base && strncmp(base, "libpython3", 10) == 0) {
        snprintf((char*)found, PATH_MAX, "%s", name);
        return 1;
    }
    return 0;
}

static int try_libpython(const char* path, char* tried, size_t size)
{
    if (!path || !*path) return 0;
    dlerror();
    void* handle = dlopen(path, RTLD_NOW | RTLD_GLOBAL);
    if (handle && dlsym(handle, "Py_IsInitialized")) {
        snprintf(load_info, sizeof load_info, "loaded libpython %s", path);
        return 1;
    }
    const char* reason = dlerror();
    append(tried, size, "\n  %s: %s", path,
           handle ? "no Py_IsInitialized in it" : (reason ? reason : "not found"));
    return 0;
}

int ensure_libpython(void)
{
    if (dlsym(RTLD_DEFAULT, "Py_IsInitialized")) {
        snprintf(load_info, sizeof load_info, "the process already has Python (global scope)");
        return 1;
    }
    char mapped[PATH_MAX] = "";
    if (dl_iterate_phdr(find_mapped_libpython, mapped) && mapped[0]) {
        /* mapped with RTLD_LOCAL: promote that same copy to the global scope */
        if (dlopen(mapped, RTLD_NOW | RTLD_GLOBAL | RTLD_NOLOAD) &&
            dlsym(RTLD_DEFAULT, "Py_IsInitialized")) {
            snprintf(load_info, sizeof load_info, "made the process's %s global", mapped);
            return 1;
        }
        snprintf(load_error, sizeof load_error, "the process has %s loaded privately and it "
                 "could not be made global; not loading a second libpython", mapped);
        return 0;
    }
    char tried[1536] = "";
    const char* chosen = getenv("SMA_FMU_LIBPYTHON");
    if (chosen && *chosen) {
        if (try_libpython(chosen, tried, sizeof tried)) return 1;
        snprintf(load_error, sizeof load_error, "SMA_FMU_LIBPYTHON=%s could not be loaded:%s",
                 chosen, tried);
        return 0;
    }
    if (try_libpython(SMA_FRONT_LIBPYTHON, tried, sizeof tried) ||
        try_libpython(SMA_FRONT_LIBPYTHON_SONAME, tried, sizeof tried) ||
        try_libpython(DEBIAN_LIBPYTHON, tried, sizeof tried))
        return 1;
    snprintf(load_error, sizeof load_error,
             "this FMU runs Python and needs a shared libpython (%s), but none was found. "
             "Tried:%s\nSet SMA_FMU_LIBPYTHON to the full path of a libpython3 shared library "
             "(python3 -c \"import sysconfig,os;print(os.path.join(sysconfig.get_config_var("
             "'LIBDIR'),sysconfig.get_config_var('INSTSONAME')))\" prints it for a Python built "
             "with --enable-shared), or LD_PRELOAD it.", SMA_FRONT_LIBPYTHON_SONAME, tried);
    return 0;
}

static void release_kept_state(void* kept);

int resolve_python_api(void)
{
#define LOOKUP(field, name) *(void**)(&py.field) = dlsym(RTLD_DEFAULT, name)
    LOOKUP(IsInitialized, "Py_IsInitialized");
    LOOKUP(GILState_Ensure, "PyGILState_Ensure");
    LOOKUP(GILState_GetThisThreadState, "PyGILState_GetThisThreadState");
    LOOKUP(Eval_SaveThread, "PyEval_SaveThread");
    LOOKUP(Eval_RestoreThread, "PyEval_RestoreThread");
    LOOKUP(IsFinalizing, "Py_IsFinalizing");
    if (!py.IsFinalizing) LOOKUP(IsFinalizing, "_Py_IsFinalizing");
    LOOKUP(ThreadState_Clear, "PyThreadState_Clear");
    LOOKUP(ThreadState_DeleteCurrent, "PyThreadState_DeleteCurrent");
#undef LOOKUP
    const char* off = getenv("SMA_FMU_NO_TSTATE");
    use_thread_state_keeper = !(off && *off && strcmp(off, "0") != 0);
    if (pthread_key_create(&kept_state_key, release_kept_state) != 0) use_thread_state_keeper = 0;
    return py.IsInitialized && py.GILState_Ensure && py.GILState_GetThisThreadState &&
           py.Eval_SaveThread && py.Eval_RestoreThread;
}

int python_is_initialized(void) { return py.IsInitialized && py.IsInitialized(); }

/* ---- one parked thread state per host thread ----------------------------------------------- */
static __thread int thread_checked; /* 1: parked one, or the thread already had one */

/* At thread exit (pthread key destructor). Not through PyGILState_Release: glibc may already
 * have cleared Python's own thread-specific slot of the exiting thread. Instead do what
 * PyGILState_Release does at counter 0. Skipped once Python is finalizing. */
static void release_kept_state(void* kept)
{
    if (!kept) return;
    if (py.ThreadState_Clear && py.ThreadState_DeleteCurrent && python_is_initialized() &&
        !(py.IsFinalizing && py.IsFinalizing())) {
        py.Eval_RestoreThread(kept);   /* takes the GIL */
        py.ThreadState_Clear(kept);
        py.ThreadState_DeleteCurrent(); /* deletes it and releases the GIL */
    }
}

void keep_thread_state(void)
{
    if (thread_checked || !use_thread_state_keeper || !python_is_initialized()) return;
    thread_checked = 1;
    if (py.GILState_GetThisThreadState()) return; /* a Python thread: nothing to do */
    py.GILState_Ensure();             /* a new thread state, GIL taken */
    void* state = py.Eval_SaveThread(); /* GIL released, state kept (Ensure counter 1) */
    pthread_setspecific(kept_state_key, state);
}

/* pythonfmu initializes Python in its first fmi2Instantiate, guarded by a mutex private to
 * each copy of pythonfmu's binary: two different FMUs instantiated at the same moment can
 * both call Py_Initialize and crash. Fronts share no memory, but they share the libpython
 * file: an flock on it serializes first instantiations until Python is initialized. */
fmi2Component instantiate_backend_locked(fmi2String name, fmi2Type type, fmi2String guid,
                                         fmi2String uri, const fmi2CallbackFunctions* cb,
                                         fmi2Boolean visible)
{
    /* loggingOn = true: pythonfmu would drop every message otherwise; the front filters */
    if (python_is_initialized()) return backend.Instantiate(name, type, guid, uri, cb, visible, 1);
    int fd = -1;
    Dl_info info;
    if (dladdr(*(void**)&py.IsInitialized, &info) && info.dli_fname && info.dli_fname[0] == '/')
        fd = open(info.dli_fname, O_RDONLY | O_CLOEXEC);
    if (fd >= 0)
        while (flock(fd, LOCK_EX) != 0 && errno == EINTR) {
        }
    fmi2Component component = backend.Instantiate(name, type, guid, uri, cb, visible, 1);
    if (fd >= 0) close(fd); /* releases the lock */
    return component;
}

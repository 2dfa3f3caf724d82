/*
 * platform.h - what the front needs from the operating system: libraries, files, a mutex,
 * one thread-local slot with a destructor, the environment. platform_posix.c implements it
 * for Linux, platform_windows.c for Windows (each file compiles to nothing on the other).
 * Paths are UTF-8 on both; the Windows layer converts them to UTF-16 for the system.
 */
#ifndef SMA_FMU_PLATFORM_H
#define SMA_FMU_PLATFORM_H

#include <stddef.h>
#include <stdio.h>

#ifdef _WIN32
#define EXPORT __declspec(dllexport)
#define LIBRARY_SUFFIX ".dll"
#define PRINTF_LIKE(f, a) __attribute__((format(gnu_printf, f, a)))
#else
#define EXPORT __attribute__((visibility("default")))
#define LIBRARY_SUFFIX ".so"
#define PRINTF_LIKE(f, a) __attribute__((format(printf, f, a)))
#endif

#define PATH_SIZE 4096

/* ---- libraries ----------------------------------------------------------------------------- */
typedef void* Library;
/* NULL on failure, with the system's reason in err. global: symbols for later libraries
 * (RTLD_GLOBAL; ignored on Windows). pinned: never unloaded (RTLD_NODELETE / pinned). */
Library library_open(const char* path, int global, int pinned, char* err, size_t errlen);
void* library_symbol(Library library, const char* name);
void library_close(Library library);
/* The file of the front library itself; 0 if unknown. */
int self_path(char* path, size_t size);
/* Keep the front library loaded until the process ends, whatever the host unloads. */
void pin_self(void);

/* ---- files (UTF-8 paths) ------------------------------------------------------------------- */
FILE* file_open(const char* path, const char* mode);
int is_directory(const char* path);
int is_readable_file(const char* path);
/* An exclusive lock on the whole of `path` (flock / LockFileEx), for one process at a time;
 * NULL if the file cannot be opened. Waits for the lock. */
void* lock_file(const char* path);
void unlock_file(void* lock);

/* ---- threads ------------------------------------------------------------------------------- */
typedef struct {
    void* opaque[8]; /* pthread_mutex_t (40 bytes on x86-64 glibc) or an SRWLOCK */
} Mutex;
#define MUTEX_INITIALIZER {{0}}
void mutex_lock(Mutex* mutex);
void mutex_unlock(Mutex* mutex);
/* One thread-local slot; `at_thread_exit` gets a thread's non-NULL value when it ends. */
int thread_slot_create(void (*at_thread_exit)(void*));
void* thread_slot_get(void);
void thread_slot_set(void* value);

/* ---- environment --------------------------------------------------------------------------- */
/* The variable `name` (UTF-8) into value; 0 if unset or empty. */
int environment(const char* name, char* value, size_t size);

#endif

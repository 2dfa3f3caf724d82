/*
 * platform_posix.c - platform.h for Linux: dlopen, dladdr, flock, pthreads.
 */
#ifndef _WIN32
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "platform.h"

_Static_assert(sizeof(pthread_mutex_t) <= sizeof(Mutex), "Mutex too small for pthread_mutex_t");

Library library_open(const char* path, int global, int pinned, char* err, size_t errlen)
{
    dlerror();
    void* handle = dlopen(path, RTLD_NOW | (global ? RTLD_GLOBAL : RTLD_LOCAL) |
                                    (pinned ? RTLD_NODELETE : 0));
    if (!handle && err) {
        const char* reason = dlerror();
        snprintf(err, errlen, "%s", reason ? reason : "not found");
    }
    return handle;
}

void* library_symbol(Library library, const char* name) { return dlsym(library, name); }

void library_close(Library library)
{
    if (library) dlclose(library);
}

int self_path(char* path, size_t size)
{
    Dl_info self;
    if (!dladdr((void*)&self_path, &self) || !self.dli_fname || !*self.dli_fname) return 0;
    snprintf(path, size, "%s", self.dli_fname);
    return strlen(self.dli_fname) < size;
}

void pin_self(void)
{
    char path[PATH_SIZE];
    if (self_path(path, sizeof path)) dlopen(path, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
}

FILE* file_open(const char* path, const char* mode) { return fopen(path, mode); }

int is_directory(const char* path)
{
    struct stat info;
    return stat(path, &info) == 0 && S_ISDIR(info.st_mode);
}

int is_readable_file(const char* path)
{
    struct stat info;
    return stat(path, &info) == 0 && S_ISREG(info.st_mode) && access(path, R_OK) == 0;
}

void* lock_file(const char* path)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return NULL;
    while (flock(fd, LOCK_EX) != 0 && errno == EINTR) {
    }
    return (void*)(long)(fd + 1);
}

void unlock_file(void* lock)
{
    if (lock) close((int)(long)lock - 1); /* releases the lock */
}

void mutex_lock(Mutex* mutex) { pthread_mutex_lock((pthread_mutex_t*)mutex); }
void mutex_unlock(Mutex* mutex) { pthread_mutex_unlock((pthread_mutex_t*)mutex); }

static pthread_key_t slot_key;

int thread_slot_create(void (*at_thread_exit)(void*))
{
    return pthread_key_create(&slot_key, at_thread_exit) == 0;
}

void* thread_slot_get(void) { return pthread_getspecific(slot_key); }
void thread_slot_set(void* value) { pthread_setspecific(slot_key, value); }

int environment(const char* name, char* value, size_t size)
{
    const char* text = getenv(name);
    if (!text || !*text || strlen(text) >= size) return 0;
    snprintf(value, size, "%s", text);
    return 1;
}
#endif

/* Which fmi2Component pointers are instances of this binary: live, freed, or neither.
 *
 * A pointer a host passes in is looked up here before anything reads through it, so a call
 * after fmi2FreeInstance, fmi2FreeInstance twice, or a pointer that never was an instance is
 * refused instead of reading freed or foreign memory. fmi2FreeInstance releases what an
 * instance holds but keeps its struct (and name, for the message), marked freed, in a ring
 * of the last KEPT_FREED: while a host may still call with the old pointer, the allocator
 * cannot give that address to a new instance. The oldest one leaves the ring when a newer
 * one enters it and is released then. Every instance is linked into one of BUCKETS chains
 * by its own `chain` field (no table to grow, so registering cannot fail); a chain is walked
 * under the lock and only through registered, allocated instances. Refusals go to stderr,
 * not to the host's logger: after fmi2FreeInstance the logger may be gone. When the library
 * is unloaded the ring is released (a destructor on ELF, DllMain on Windows): no pointer
 * into this library can be called after that, so what it guarded is gone with it. */
#ifndef _WIN32
#define _POSIX_C_SOURCE 200809L
#endif
#include "fp_contract.h"
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "layer.h"

#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
static SRWLOCK registry_lock = SRWLOCK_INIT;
#define LOCK() AcquireSRWLockExclusive(&registry_lock)
#define UNLOCK() ReleaseSRWLockExclusive(&registry_lock)
#else
#include <pthread.h>
static pthread_mutex_t registry_lock = PTHREAD_MUTEX_INITIALIZER;
#define LOCK() pthread_mutex_lock(&registry_lock)
#define UNLOCK() pthread_mutex_unlock(&registry_lock)
#endif

#define BUCKETS 1021u       /* a prime: chains stay short for live + kept instances */
#define KEPT_FREED 1024u    /* freed instances kept allocated (about 0.7 KiB each) */

static Instance *chains[BUCKETS];
static Instance *kept[KEPT_FREED];  /* ring of freed instances, oldest at `oldest` */
static size_t oldest;

static Instance **chain_of(const void *pointer)
{
    uintptr_t bits = (uintptr_t)pointer;
    return &chains[(size_t)((bits >> 4) % BUCKETS)];
}

/* The link pointing at `pointer` in its chain, or NULL: compares addresses only, reads
 * nothing through `pointer`. Called with the lock held. */
static Instance **link_to(const void *pointer)
{
    Instance **link = chain_of(pointer);
    while (*link && (const void *)*link != pointer) link = &(*link)->chain;
    return *link ? link : NULL;
}

void layer_register(Instance *in)
{
    Instance **head = chain_of(in);
    LOCK();
    in->freed = 0;
    in->chain = *head;
    *head = in;
    UNLOCK();
}

/* One stderr line for a refused pointer; `name` is the freed instance's (a "%s" argument). */
static void refused(const char *function, const void *pointer, const char *name)
{
    if (name)
        fprintf(stderr, "sma-fmu native: %s: refused: instance '%s' was freed by "
                "%.4sFreeInstance\n", function, name, function);
    else
        fprintf(stderr, "sma-fmu native: %s: refused: %p is no instance of this FMU (not made "
                "by %.4sInstantiate, or freed over %u instances ago)\n", function, pointer, function,
                KEPT_FREED);
    fflush(stderr);
}

/* Looks `pointer` up; live: returns it (with `mark` it is marked freed and no longer live);
 * else writes why to stderr and returns NULL. */
static Instance *find(const void *pointer, const char *function, int mark)
{
    char name[160] = "";
    Instance **link;
    Instance *in = NULL;
    int freed = 0;
    if (!pointer) return NULL;  /* NULL is no instance, and says so without a message */
    LOCK();
    link = link_to(pointer);
    if (link && (*link)->freed) {
        freed = 1;
        snprintf(name, sizeof name, "%s", (*link)->name ? (*link)->name : "?");
    } else if (link) {
        in = *link;
        if (mark) in->freed = 1;
    }
    UNLOCK();
    if (!in) refused(function, pointer, freed ? name : NULL);
    return in;
}

Instance *layer_live(const void *pointer, const char *function)
{
    return find(pointer, function, 0);
}

Instance *layer_retire(const void *pointer, const char *function)
{
    return find(pointer, function, 1);
}

void layer_keep(Instance *in)
{
    Instance *dropped;
    Instance **link;
    LOCK();
    dropped = kept[oldest];
    kept[oldest] = in;
    oldest = (oldest + 1) % KEPT_FREED;
    link = dropped ? link_to(dropped) : NULL;
    if (link) *link = dropped->chain;
    UNLOCK();
    if (dropped) {
        free(dropped->name);
        free(dropped);
    }
}

/* Release the ring of freed instances (the library is being unloaded). Live instances are
 * the host's to free and are left alone. */
static void release_kept(void)
{
    size_t i;
    LOCK();
    for (i = 0; i < KEPT_FREED; ++i) {
        Instance *dropped = kept[i];
        Instance **link = dropped ? link_to(dropped) : NULL;
        if (link) *link = dropped->chain;
        kept[i] = NULL;
        if (dropped) {
            free(dropped->name);
            free(dropped);
        }
    }
    oldest = 0;
    UNLOCK();
}

#ifdef _WIN32
BOOL WINAPI DllMain(HINSTANCE module, DWORD reason, LPVOID reserved);
BOOL WINAPI DllMain(HINSTANCE module, DWORD reason, LPVOID reserved)
{
    (void)module;
    /* reserved != NULL: the process is ending, the system takes the memory back */
    if (reason == DLL_PROCESS_DETACH && reserved == NULL) release_kept();
    return TRUE;
}
#elif defined(__GNUC__)
__attribute__((destructor)) static void unloaded(void) { release_kept(); }
#endif

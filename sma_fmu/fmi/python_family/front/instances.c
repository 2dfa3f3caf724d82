/*
 * instances.c - the instances of this copy of the front: live ones, and freed ones kept
 * for a while, so that fmi2FreeInstance twice, or any call after it, is refused instead of
 * reading freed memory.
 *
 * Every pointer a call gets is looked up in a hash set before it is used. A freed
 * instance's memory is not given back at once: it stays in the set, marked freed (its name
 * kept for the message), so the allocator cannot hand its address to a new instance while
 * a host may still call with it. The last FREED_KEPT freed instances are kept (a few
 * hundred bytes each); older ones are released. A pointer that is in neither (never an
 * instance, or freed long ago) is refused too. Refusals go to stderr: after fmi2FreeInstance
 * the host's logger and its environment may be gone.
 */
#define _GNU_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"

/* The logging categories an instance was given (fmi2SetDebugLogging); then, for a freed
 * instance, its name and fast-path values and the instance itself. */
void free_categories(Instance* in)
{
    for (size_t i = 0; i < in->n_categories; ++i) free(in->categories[i]);
    free(in->categories);
    in->categories = NULL;
    in->n_categories = 0;
}

void free_instance_memory(Instance* in)
{
    fast_free(&in->fast);
    free_categories(in);
    free(in->name);
    free(in);
}

#define FREED_KEPT 1024
#define DELETED ((Instance*)1)

static Mutex registry_mutex = MUTEX_INITIALIZER;
static Instance** table;         /* open addressing; NULL empty, DELETED a removed entry */
static size_t capacity, used;    /* used: live, freed and DELETED slots */
static Instance* freed[FREED_KEPT]; /* ring of freed instances still kept */
static size_t freed_next;

static size_t slot_of(const void* pointer, size_t mask)
{
    uintptr_t x = (uintptr_t)pointer;
    x ^= x >> 17;
    x *= (uintptr_t)0x9E3779B97F4A7C15ull;
    return (size_t)(x >> 7) & mask;
}

/* The slot holding `pointer`, or NULL. Caller holds the mutex. */
static Instance** lookup(const void* pointer)
{
    if (!table) return NULL;
    for (size_t i = slot_of(pointer, capacity - 1), n = 0; n < capacity; i = (i + 1) & (capacity - 1), ++n) {
        if (!table[i]) return NULL;
        if (table[i] == pointer) return &table[i];
    }
    return NULL;
}

static int insert(Instance* in)
{
    if ((used + 1) * 2 > capacity) { /* grow (and drop DELETED slots) */
        size_t size = capacity ? capacity * 2 : 64;
        Instance** grown = (Instance**)calloc(size, sizeof *grown);
        if (!grown) return 0;
        size_t count = 0;
        for (size_t i = 0; i < capacity; ++i) {
            if (!table[i] || table[i] == DELETED) continue;
            size_t j = slot_of(table[i], size - 1);
            while (grown[j]) j = (j + 1) & (size - 1);
            grown[j] = table[i];
            ++count;
        }
        free(table);
        table = grown;
        capacity = size;
        used = count;
    }
    size_t j = slot_of(in, capacity - 1);
    while (table[j] && table[j] != DELETED) j = (j + 1) & (capacity - 1);
    if (!table[j]) ++used;
    table[j] = in;
    return 1;
}

int register_instance(Instance* in)
{
    mutex_lock(&registry_mutex);
    int done = insert(in);
    mutex_unlock(&registry_mutex);
    return done;
}

Instance* live_instance(fmi2Component c, const char* function)
{
    if (!c) return NULL;
    mutex_lock(&registry_mutex);
    Instance** slot = lookup(c);
    Instance* in = slot ? *slot : NULL;
    char name[256] = "";
    if (in && in->freed) {
        snprintf(name, sizeof name, "%s", in->name ? in->name : "?");
        in = NULL;
    }
    mutex_unlock(&registry_mutex);
    if (in) return in;
    if (*name)
        fprintf(stderr, "sma-fmu front: %s: refused: instance '%s' was freed by fmi2FreeInstance\n",
                function, name);
    else
        fprintf(stderr, "sma-fmu front: %s: refused: %p is not an instance of this FMU (never "
                "returned by fmi2Instantiate, or freed long ago)\n", function, c);
    fflush(stderr);
    return NULL;
}

int retire_instance(fmi2Component c)
{
    Instance* released = NULL;
    mutex_lock(&registry_mutex);
    Instance** slot = c ? lookup(c) : NULL;
    Instance* in = slot ? *slot : NULL;
    int was_live = in && !in->freed;
    if (was_live) {
        in->freed = 1;
        Instance* oldest = freed[freed_next];
        freed[freed_next] = in;
        freed_next = (freed_next + 1) % FREED_KEPT;
        if (oldest) {
            Instance** old_slot = lookup(oldest);
            if (old_slot) *old_slot = DELETED;
            released = oldest;
        }
    }
    mutex_unlock(&registry_mutex);
    if (released) free_instance_memory(released);
    return was_live;
}

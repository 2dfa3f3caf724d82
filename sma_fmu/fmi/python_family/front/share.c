/*
 * share.c - finding a copy of the front that already owns pythonfmu's binary (Linux).
 *
 * Two copies may share a backend when their backend files have the same GNU build ID (the
 * linker's hash of the binary: the same pythonfmu build). The owner exports its record,
 * sma_fmu_front_share (front.h); a copy looks for it among the libraries the process has
 * loaded. The owner may have been loaded from a folder that no longer exists: the record
 * lives in memory, so that does not matter. On Windows nothing is shared (each copy of the
 * front is pinned and loads its own backend), so both functions report nothing there.
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "front.h"

#ifndef _WIN32
#include <dlfcn.h>
#include <elf.h>
#include <link.h>

int backend_build_id(const char* path, unsigned char* id, size_t* size)
{
    FILE* file = fopen(path, "rb");
    if (!file) return 0;
    int found = 0;
    ElfW(Ehdr) header;
    if (fread(&header, sizeof header, 1, file) == 1 && memcmp(header.e_ident, ELFMAG, SELFMAG) == 0 &&
        header.e_phentsize == sizeof(ElfW(Phdr)) && header.e_phnum < 256) {
        for (unsigned i = 0; i < header.e_phnum && !found; ++i) {
            ElfW(Phdr) segment;
            if (fseek(file, (long)(header.e_phoff + i * sizeof segment), SEEK_SET) != 0 ||
                fread(&segment, sizeof segment, 1, file) != 1)
                break;
            if (segment.p_type != PT_NOTE || segment.p_filesz > 65536) continue;
            unsigned char* notes = (unsigned char*)malloc(segment.p_filesz);
            if (!notes) break;
            size_t align = segment.p_align == 8 ? 8 : 4;
            if (fseek(file, (long)segment.p_offset, SEEK_SET) == 0 &&
                fread(notes, segment.p_filesz, 1, file) == 1) {
                size_t at = 0;
                while (at + sizeof(ElfW(Nhdr)) <= segment.p_filesz) {
                    ElfW(Nhdr) note;
                    memcpy(&note, notes + at, sizeof note);
                    size_t name_at = at + sizeof note;
                    size_t desc_at = name_at + ((note.n_namesz + align - 1) & ~(align - 1));
                    size_t next = desc_at + ((note.n_descsz + align - 1) & ~(align - 1));
                    if (desc_at + note.n_descsz > segment.p_filesz) break;
                    if (note.n_type == NT_GNU_BUILD_ID && note.n_namesz == 4 &&
                        memcmp(notes + name_at, "GNU", 4) == 0 && note.n_descsz > 0 &&
                        note.n_descsz <= 64) {
                        memcpy(id, notes + desc_at, note.n_descsz);
                        *size = note.n_descsz;
                        found = 1;
                        break;
                    }
                    at = next;
                }
            }
            free(notes);
        }
    }
    fclose(file);
    return found;
}

typedef struct {
    char** names;
    size_t count, capacity;
} Names;

/* dl_iterate_phdr callback: every loaded library named *.so (a front is <model>.so). */
static int collect(struct dl_phdr_info* info, size_t size, void* data)
{
    (void)size;
    Names* names = (Names*)data;
    const char* name = info->dlpi_name;
    size_t n = name ? strlen(name) : 0;
    if (n < 4 || strcmp(name + n - 3, ".so") != 0) return 0;
    if (names->count == names->capacity) {
        size_t capacity = names->capacity ? 2 * names->capacity : 64;
        char** grown = (char**)realloc(names->names, capacity * sizeof *grown);
        if (!grown) return 1;
        names->names = grown;
        names->capacity = capacity;
    }
    char* copy = strdup(name);
    if (copy) names->names[names->count++] = copy;
    return 0;
}

const FrontShare* find_owner(const unsigned char* id, size_t size)
{
    Names names = {NULL, 0, 0};
    dl_iterate_phdr(collect, &names); /* no dlopen inside: the loader's lock is held there */
    const FrontShare* owner = NULL;
    for (size_t i = 0; i < names.count; ++i) {
        if (!owner) {
            void* handle = dlopen(names.names[i], RTLD_LAZY | RTLD_NOLOAD);
            const FrontShare* offer = handle ? (const FrontShare*)dlsym(handle, "sma_fmu_front_share")
                                             : NULL;
            if (offer && offer != &sma_fmu_front_share &&
                memcmp(offer->magic, SHARE_MAGIC, sizeof offer->magic) == 0 &&
                offer->abi == SHARE_ABI && __atomic_load_n(&offer->ready, __ATOMIC_ACQUIRE) &&
                offer->backend_id_size == size && memcmp(offer->backend_id, id, size) == 0)
                owner = offer; /* the owner is pinned: it stays after dlclose */
            if (handle) dlclose(handle);
        }
        free(names.names[i]);
    }
    free(names.names);
    return owner;
}

#else
int backend_build_id(const char* path, unsigned char* id, size_t* size)
{
    (void)path; (void)id; (void)size;
    return 0;
}

const FrontShare* find_owner(const unsigned char* id, size_t size)
{
    (void)id; (void)size;
    return NULL;
}
#endif

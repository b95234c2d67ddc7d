/* The memory of one layout reading: blocks of aligned units, freed at once. */
#include "toml.h"

#include <stdlib.h>

typedef union {
    long double a;
    long long b;
    void *c;
    double d;
} Aligned;

struct ArenaBlock {
    ArenaBlock *next;
    size_t used, size;
    Aligned data[];
};

void *arena_alloc(Arena *arena, size_t count)
{
    ArenaBlock *block = arena->blocks;
    size_t units = (count + sizeof(Aligned) - 1) / sizeof(Aligned);
    if (units == 0) {
        units = 1;
    }
    if (block == NULL || block->size - block->used < units) {
        size_t size = units > 4096 ? units : 4096;
        block = malloc(sizeof(ArenaBlock) + size * sizeof(Aligned));
        if (block == NULL) {
            return NULL;
        }
        block->next = arena->blocks;
        block->used = 0;
        block->size = size;
        arena->blocks = block;
    }
    block->used += units;
    return block->data + block->used - units;
}

void arena_free(Arena *arena)
{
    while (arena->blocks != NULL) {
        ArenaBlock *next = arena->blocks->next;
        free(arena->blocks);
        arena->blocks = next;
    }
}

/* The messages of the native FMUs' shared layer (fmu_messages.h). */
#include "fmu_messages.h"

#include <stdarg.h>
#include <string.h>

void append_pieces(char *out, size_t size, const char *first, va_list pieces)
{
    size_t used = strlen(out);
    const char *piece;
    for (piece = first; piece != NULL; piece = va_arg(pieces, const char *)) {
        size_t length = strlen(piece);
        if (used + 1 >= size) {
            break;
        }
        if (length > size - 1 - used) {
            length = size - 1 - used;
        }
        memcpy(out + used, piece, length);
        used += length;
        out[used] = '\0';
    }
}

void messages_add(Messages *out, const char *first, ...)
{
    va_list pieces;
    if (out->count >= FMU_MAX_MESSAGES) {
        return;
    }
    out->text[out->count][0] = '\0';
    va_start(pieces, first);
    append_pieces(out->text[out->count], FMU_MESSAGE_SIZE, first, pieces);
    va_end(pieces);
    out->count++;
}

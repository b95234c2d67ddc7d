/* The messages of the native FMUs' shared layer: the reasons a call or a check gathers before the
 * layer logs them (a refusal, a notice), each cut to FMU_MESSAGE_SIZE bytes. */
#ifndef FMU_MESSAGES_H
#define FMU_MESSAGES_H

#include <stdarg.h>
#include <stddef.h>

#define FMU_MESSAGE_SIZE 1024 /* a message names a layout file by its absolute path: room for a long one */
#define FMU_MAX_MESSAGES 48

typedef struct {
    int count;
    char text[FMU_MAX_MESSAGES][FMU_MESSAGE_SIZE];
} Messages;

/* Appends the text pieces (``first`` and the rest, NULL ending them) to ``out`` (``size`` bytes), cut to fit. */
void append_pieces(char *out, size_t size, const char *first, va_list pieces);
/* Adds one message, the text pieces ``first`` ... NULL; none past FMU_MAX_MESSAGES. */
void messages_add(Messages *out, const char *first, ...);

#endif

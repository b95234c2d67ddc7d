/* What the modules of the native FMUs' shared layer call in each other (fmu_instance.h is the
 * layer's interface to the FMI functions and the models). */
#ifndef FMU_LAYER_H
#define FMU_LAYER_H

#include <stdarg.h>
#include <stddef.h>

#include "fmu_instance.h"

void append_pieces(char *out, size_t size, const char *first, va_list pieces);
void parameter_errors(const ModelData *data, Messages *out);
void input_errors(const ModelData *data, Messages *out);
void output_errors(const ModelData *data, Messages *out, Failure *failure);
void restored_errors(const ModelData *data, double start_time, Messages *out);
char *copy_text(const char *text, size_t length);
void free_strings(char *strings[MODEL_VARIABLE_COUNT]);
int copy_strings(char *const from[MODEL_VARIABLE_COUNT], char *to[MODEL_VARIABLE_COUNT]);
size_t characters(const char *text, size_t length);

#endif

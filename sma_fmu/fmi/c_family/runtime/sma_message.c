/* Error messages of the C runtime (see sma_message.h). */
#include "fp_contract.h"
#include "sma_message.h"

#include <stdarg.h>
#include <stdio.h>

int sma_message_set(SmaMessage *message, const char *format, ...)
{
    va_list arguments;
    if (message == NULL) {
        return 1;
    }
    va_start(arguments, format);
    vsnprintf(message->text, sizeof message->text, format, arguments);
    va_end(arguments);
    return 1;
}

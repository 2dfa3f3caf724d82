/* The log category of an FMI status (log_category.h). */
#include "log_category.h"

const char *log_status_category(int status)
{
    switch (status) {
    case 1: return "logStatusWarning";
    case 2: return "logStatusDiscard";
    case 3: return "logStatusError";
    case 4: return "logStatusFatal";
    default: return "logAll";
    }
}

/* The log category of an FMI status, as both families' model descriptions declare them
 * (logStatusWarning, logStatusDiscard, logStatusError, logStatusFatal, else logAll). */
#ifndef SMA_LOG_CATEGORY_H
#define SMA_LOG_CATEGORY_H

/* `status`: an fmi2Status value (0 OK, 1 Warning, 2 Discard, 3 Error, 4 Fatal, 5 Pending). */
const char *log_status_category(int status);

#endif

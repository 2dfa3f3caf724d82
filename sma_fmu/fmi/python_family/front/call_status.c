/*
 * call_status.c - the status a front call returns: a refusal (logged, with the function's
 * name) or a forwarded call's status, made worse by what the slave logged during it.
 *
 * The lowest layer of the front's calls: fmi2_exports.c, fmi2_states.c and fast_path.c call
 * it; it calls only the host logger (host_log.c). No module calls back up into
 * fmi2_exports.c.
 */
#include "front.h"

fmi2Status refuse(Instance* in, fmi2Status status, const char* function, const char* why)
{
    host_logf(in, status, "%s: %s", function, why);
    return status;
}

/* Status of a forwarded call: the backend's, or worse if the slave logged worse. */
fmi2Status finish(Instance* in, fmi2Status status)
{
    if (status == fmi2Fatal) in->dead = 1;
    return in->logged_status > status ? in->logged_status : status;
}

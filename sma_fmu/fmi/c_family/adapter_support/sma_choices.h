/* Settings that choose among names, carried by FMI Integer parameters holding a code
 * (slave_support/choices.py): hysteresis_mode 1 = continuous, 2 = switch; inverse
 * 1 = major, 2 = minor-loop; shaping 1 = none, 2 = reachable; modulation 1 = pwm,
 * 2 = linear. The runtime keeps the names. */
#ifndef SMA_CHOICES_H
#define SMA_CHOICES_H

#include "sma_message.h"

/* The name of `code` for `parameter` ("hysteresis_mode", "inverse", "shaping" or "modulation")
 * in *name, or refused as choice_name does: "inverse must be 1 (major) or 2 (minor-loop), got 3". */
int choice_name(const char *parameter, int code, const char **name, SmaMessage *message);

#endif

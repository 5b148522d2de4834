/* pm_interrupt: the process's record of SIGINT/SIGTERM, read by the run's
 * loop and polled inside long solves and setups so that a signal stops
 * them within a second or two. */
#ifndef PM_INTERRUPT_H
#define PM_INTERRUPT_H

#include <signal.h>

#include "pm_error.h"

/* The signal received (SIGINT or SIGTERM), 0 if none.  Sticky for the
 * process: once set, it stays set. */
int pm_interrupt_signal(void);

/* "SIGINT" or "SIGTERM" (any other number: "SIGTERM"). */
const char *pm_interrupt_name(int sig);

/* Catch SIGINT and SIGTERM (old: the handlers before, for
 * pm_interrupt_release).  once: a second signal half a second or more
 * after the first acts as usual (kills a run that does not reach a point
 * where it polls); signals closer together are one request (GNU timeout
 * sends its child SIGTERM and then its whole process group the same). */
void pm_interrupt_catch(struct sigaction old[2], int once);
void pm_interrupt_release(const struct sigaction old[2]);

/* PM_ERR_INTERRUPTED, with a message naming the signal and `what` (e.g.
 * "while reading the image"), if a signal was received; else PM_SUCCESS
 * and nothing recorded.  For long setups to poll between pieces of work. */
pm_err pm_interrupt_check(const char *what);

#endif

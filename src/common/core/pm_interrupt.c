/* pm_interrupt: the SIGINT/SIGTERM flag of the process and its handler. */
#include "pm_interrupt.h"

#include <errno.h>
#include <string.h>
#include <time.h>

static volatile sig_atomic_t interrupt_signal;
static volatile sig_atomic_t catch_once;
static struct timespec first_at; /* the first signal's time */

/* Seconds from the first signal to now (async-signal-safe). */
static double since_first(void) {
  struct timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  return (double)(now.tv_sec - first_at.tv_sec) +
         1e-9 * (double)(now.tv_nsec - first_at.tv_nsec);
}

/* A second signal kills (the default action, raised again) once half a
 * second has passed since the first: a second Ctrl-C, or a scheduler that
 * escalates.  The two copies GNU timeout sends at once (to its child and to
 * its process group) are one request. */
static void on_interrupt(int sig) {
  if (!interrupt_signal) {
    clock_gettime(CLOCK_MONOTONIC, &first_at);
    interrupt_signal = sig;
    return;
  }
  if (catch_once && since_first() >= 0.5) {
    signal(sig, SIG_DFL);
    raise(sig);
  }
}

int pm_interrupt_signal(void) { return interrupt_signal; }

const char *pm_interrupt_name(int sig) {
  return sig == SIGINT ? "SIGINT" : "SIGTERM";
}

void pm_interrupt_catch(struct sigaction old[2], int once) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;
  catch_once = once;
  sigaction(SIGINT, &sa, &old[0]);
  sigaction(SIGTERM, &sa, &old[1]);
}

void pm_interrupt_release(const struct sigaction old[2]) {
  /* A signal's copies sent at once may still be on their way: they find
   * this handler, not the one before (at most half a second's wait, and
   * only after a signal). */
  if (interrupt_signal && catch_once) {
    const double left = 0.5 - since_first();
    if (left > 0) {
      struct timespec rest;
      rest.tv_sec = 0;
      rest.tv_nsec = (long)(left * 1e9);
      while (nanosleep(&rest, &rest) != 0 && errno == EINTR) {
      }
    }
  }
  sigaction(SIGINT, &old[0], NULL);
  sigaction(SIGTERM, &old[1], NULL);
}

pm_err pm_interrupt_check(const char *what) {
  const int sig = interrupt_signal;
  if (!sig) return PM_SUCCESS;
  return PM_ERROR(PM_ERR_INTERRUPTED, "interrupted by %s %s",
                  pm_interrupt_name(sig), what);
}

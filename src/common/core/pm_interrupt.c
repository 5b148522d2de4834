/* pm_interrupt: the SIGINT/SIGTERM flag of the process and its handler. */
#include "pm_interrupt.h"

#include <string.h>

static volatile sig_atomic_t interrupt_signal;

static void on_interrupt(int sig) { interrupt_signal = sig; }

int pm_interrupt_signal(void) { return interrupt_signal; }

const char *pm_interrupt_name(int sig) {
  return sig == SIGINT ? "SIGINT" : "SIGTERM";
}

void pm_interrupt_catch(struct sigaction old[2], int once) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_interrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = once ? SA_RESETHAND : 0;
  sigaction(SIGINT, &sa, &old[0]);
  sigaction(SIGTERM, &sa, &old[1]);
}

void pm_interrupt_release(const struct sigaction old[2]) {
  sigaction(SIGINT, &old[0], NULL);
  sigaction(SIGTERM, &old[1], NULL);
}

pm_err pm_interrupt_check(const char *what) {
  const int sig = interrupt_signal;
  if (!sig) return PM_SUCCESS;
  return PM_ERROR(PM_ERR_INTERRUPTED, "interrupted by %s %s",
                  pm_interrupt_name(sig), what);
}

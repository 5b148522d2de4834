/* proc-account: where a command's CPU goes, process by process.  Loaded
 * into every process of a command (LD_PRELOAD), it appends one line to the
 * file PROC_ACCOUNT names when the process leaves by exit or a return from
 * main: its own user and system CPU seconds (getrusage, children apart),
 * its minor page faults, its program and its command line.  Processes that
 * leave by _exit or a signal (the isolated readers' children, runs stopped
 * by the tests) write nothing.
 *
 *   cc -O2 -shared -fPIC benchmarks/proc-account.c -o /tmp/proc-account.so
 *   LD_PRELOAD=/tmp/proc-account.so PROC_ACCOUNT=/tmp/account.txt \
 *     ctest --test-dir build -j2
 *
 * Lines: "USER SYSTEM FAULTS PROGRAM | COMMAND LINE". */
#define _GNU_SOURCE
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

__attribute__((destructor)) static void account(void) {
  const char *path = getenv("PROC_ACCOUNT");
  if (!path) return;
  char exe[256] = {0};
  ssize_t k = readlink("/proc/self/exe", exe, sizeof exe - 1);
  exe[k > 0 ? k : 0] = '\0';
  char cmd[200] = {0};
  int fd = open("/proc/self/cmdline", O_RDONLY);
  ssize_t m = fd >= 0 ? read(fd, cmd, sizeof cmd - 1) : 0;
  if (fd >= 0) close(fd);
  if (m < 0) m = 0;
  cmd[m] = '\0';
  for (ssize_t i = 0; i < m; i++)
    if (!cmd[i]) cmd[i] = ' ';
  struct rusage r;
  getrusage(RUSAGE_SELF, &r);
  char line[700];
  int n = snprintf(line, sizeof line, "%.3f %.3f %ld %s | %.150s\n",
                   r.ru_utime.tv_sec + r.ru_utime.tv_usec * 1e-6,
                   r.ru_stime.tv_sec + r.ru_stime.tv_usec * 1e-6, r.ru_minflt,
                   exe, cmd);
  /* One write in append mode: lines of processes ending together do not
   * interleave. */
  fd = open(path, O_WRONLY | O_APPEND | O_CREAT, 0644);
  if (fd < 0) return;
  if (write(fd, line, n > (int)sizeof line - 1 ? sizeof line - 1 : (size_t)n) <
      0) {
    /* nothing to do: the accounting is best effort */
  }
  close(fd);
}

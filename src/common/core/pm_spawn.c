/* pm_spawn: run another program and wait for its exit status. */
#include "pm_spawn.h"

#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

int pm_spawn_wait(char *const argv[], const char *log) {
  extern char **environ;
  posix_spawn_file_actions_t fa;
  pid_t pid;
  int st = 0, ok = -1;
  if (posix_spawn_file_actions_init(&fa) != 0) return -1;
  if ((!log || (posix_spawn_file_actions_addopen(
                    &fa, 1, log, O_WRONLY | O_CREAT | O_TRUNC, 0644) == 0 &&
                posix_spawn_file_actions_adddup2(&fa, 1, 2) == 0)) &&
      posix_spawn(&pid, argv[0], &fa, NULL, argv, environ) == 0) {
    pid_t w;
    while ((w = waitpid(pid, &st, 0)) < 0 && errno == EINTR) {
    }
    if (w == pid && WIFEXITED(st)) ok = WEXITSTATUS(st);
  }
  posix_spawn_file_actions_destroy(&fa);
  return ok;
}

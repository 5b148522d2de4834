/* pm_spawn: run another program (the Python tools, the FE referee) and wait
 * for it. */
#ifndef PM_SPAWN_H
#define PM_SPAWN_H

/* Runs the program argv[0] with arguments argv (NULL-terminated) and waits
 * for it, through EINTR.  log: the file its standard output and error go
 * to (created or truncated), or NULL to keep the caller's.  posix_spawn,
 * not fork, so no atfork handler (MPI's) runs in the child.  Returns its
 * exit status, or -1 when it did not run or did not exit normally. */
int pm_spawn_wait(char *const argv[], const char *log);

#endif

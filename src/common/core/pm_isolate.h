/* pm_isolate: a file that a third-party library reads (gmsh, HDF5) read in
 * a forked child process, so that a fault inside the library on a damaged
 * or hostile file refuses the file instead of ending the run.
 *
 * The child does the reading (job.work), writes its outcome and the result
 * (job.put) to a pipe and leaves with _exit: it calls no MPI, runs no atexit
 * handler and flushes none of the parent's streams.  The parent reads the
 * outcome and the result (job.get) and turns a child killed by a signal (a
 * segmentation fault, an abort, the CPU limit) into a refusal naming the
 * file and the library.  The child's memory, the library's models and
 * caches with it, is returned whole when it ends.
 *
 * PM_ISOLATE=0 in the environment reads in the process itself (for a
 * debugger or a fuzzer, which must see the library's frames); any other
 * value, or none, isolates. */
#ifndef PM_ISOLATE_H
#define PM_ISOLATE_H

#include <stdbool.h>
#include <stddef.h>

#include "pm_error.h"

typedef struct {
  const char *path;    /* the file read, as messages name it */
  const char *library; /* "gmsh", "HDF5" */
  const char *what;    /* what the file should be: "a mesh gmsh reads" */
  pm_err code;         /* the refusal's code (PM_ERR_MESH, PM_ERR_IO, ...) */
  double cpu_seconds;  /* the child's CPU limit (SIGXCPU past it); 0: none;
                         PM_ISOLATE_CPU_SECONDS in the environment replaces
                         a limit that is set */
  /* The reading, in the child (or in the process when not isolated). */
  pm_err (*work)(void *arg);
  /* After a work that succeeded: the child writes the result to fd
   * (pm_isolate_put), the parent reads it back into arg (pm_isolate_get).
   * NULL when the work leaves no result to pass (a check). */
  pm_err (*put)(void *arg, int fd);
  pm_err (*get)(void *arg, int fd);
  void *arg;
} pm_isolate_job;

/* A task for the parent while the next child reads (once; NULL: none):
 * what the run will need next and can do without the file, as opening a
 * library.  Called after the fork, so the child never sees it half done;
 * not called where nothing is isolated. */
void pm_isolate_meanwhile(void (*task)(void));

/* Whether reads are isolated (PM_ISOLATE unset or not "0"). */
bool pm_isolate_enabled(void);

/* Run job: job->work in a child and the result passed back, or in the
 * process when not isolated.  Returns work's outcome with its message; a
 * child stopped by a signal: job->code with "PATH: LIBRARY stopped with
 * SIGSEGV while reading it: the file is damaged or not WHAT" (SIGXCPU:
 * "... used more than N CPU seconds ..."); a child stopped by SIGINT or
 * SIGTERM, or the parent interrupted while it waits (the child is then
 * killed): PM_ERR_INTERRUPTED. */
pm_err pm_isolate_run(const pm_isolate_job *job);

/* In a child: allow it seconds more of CPU from now (a job reading files
 * one after the other gives each its own allowance); PM_ISOLATE_CPU_SECONDS
 * replaces seconds where it is set. */
void pm_isolate_cpu_limit(double seconds);

/* In a child: allow it bytes more of address space from now (malloc then
 * fails past it, and the reader with it, where a damaged file announces
 * gigabytes).  Nothing in a build with AddressSanitizer. */
void pm_isolate_memory_limit(size_t bytes);

/* Write or read n bytes through the pipe (whole, through EINTR).  A short
 * read is PM_ERR_IO ("the child ended early"), for the caller's job->get
 * to pass on. */
pm_err pm_isolate_put(int fd, const void *data, size_t n);
pm_err pm_isolate_get(int fd, void *data, size_t n);
/* An array of count items of size bytes: its count, then its bytes; read
 * into a new array (NULL for none; the caller frees it). */
pm_err pm_isolate_put_array(int fd, const void *data, size_t count,
                            size_t size);
pm_err pm_isolate_get_array(int fd, void **data, size_t *count, size_t size);

/* Whether this process is a child pm_isolate_run started (its memory, and
 * the library's state with it, is returned whole when it leaves: a reader
 * need not tidy up there). */
bool pm_isolate_in_child(void);

/* For a test or a fuzzer of the parent's side alone: the next
 * pm_isolate_run (isolated) starts no child and reads the outcome and the
 * result from fd as if a child had written them, a child that then left
 * with status 0.  The stream may be hostile: a malformed one is refused
 * with job->code naming the file. */
void pm_isolate_stream(int fd);

#endif

/* pm_isolate: a library's reading of a file in a forked child (see
 * pm_isolate.h).  The pipe carries a header (a mark, the outcome's code and
 * message), the result job->put writes, and an end mark: a result is taken
 * only when the end mark arrived, whatever became of the child after. */
#define _GNU_SOURCE
#include "pm_isolate.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include "pm_interrupt.h"
#include "pm_omp.h"

#define MARK_HEAD 0x706d6931u /* "pmi1" */
#define MARK_END 0x706d6945u  /* "pmiE" */
/* The child's status when the library called exit() (no status of ours). */
#define EXIT_BY_LIBRARY 113

bool pm_isolate_enabled(void) {
  const char *v = getenv("PM_ISOLATE");
  return !(v && strcmp(v, "0") == 0);
}

pm_err pm_isolate_put(int fd, const void *data, size_t n) {
  const char *p = data;
  while (n > 0) {
    ssize_t w = write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0)
      return PM_ERROR(PM_ERR_IO, "cannot pass a result to the parent: %s",
                      strerror(errno));
    p += w;
    n -= (size_t)w;
  }
  return PM_SUCCESS;
}

pm_err pm_isolate_get(int fd, void *data, size_t n) {
  char *p = data;
  while (n > 0) {
    ssize_t r = read(fd, p, n);
    if (r < 0 && errno == EINTR) {
      PM_CALL(pm_interrupt_check("while a child process read a file"));
      continue;
    }
    if (r <= 0)
      return PM_ERROR(PM_ERR_IO, "the child process reading a file ended "
                                 "before its result");
    p += r;
    n -= (size_t)r;
  }
  return PM_SUCCESS;
}

pm_err pm_isolate_put_array(int fd, const void *data, size_t count,
                            size_t size) {
  uint64_t n = count;
  PM_CALL(pm_isolate_put(fd, &n, sizeof n));
  return count ? pm_isolate_put(fd, data, count * size) : PM_SUCCESS;
}

pm_err pm_isolate_get_array(int fd, void **data, size_t *count, size_t size) {
  uint64_t n = 0;
  *data = NULL;
  *count = 0;
  PM_CALL(pm_isolate_get(fd, &n, sizeof n));
  if (n == 0) return PM_SUCCESS;
  PM_CHECK(n <= SIZE_MAX / size, PM_ERR_IO,
           "a child process passed an array of %llu items",
           (unsigned long long)n);
  /* Grown as the bytes arrive, so that a count no bytes follow (a child
   * that died, or lies) allocates no more than came. */
  const size_t total = (size_t)n * size;
  size_t got = 0, cap = 0;
  char *p = NULL;
  while (got < total) {
    if (got == cap) {
      cap = cap ? (cap < total / 2 ? 2 * cap : total)
                : (total < (1u << 20) ? total : (1u << 20));
      char *q = realloc(p, cap);
      if (!q) {
        free(p);
        return PM_ERROR(PM_ERR_MEMORY, "cannot allocate %llu items passed back",
                        (unsigned long long)n);
      }
      p = q;
    }
    pm_err e = pm_isolate_get(fd, p + got, cap - got);
    if (e) {
      free(p);
      return e;
    }
    got = cap;
  }
  *data = p;
  *count = (size_t)n;
  return PM_SUCCESS;
}

/* Set in a child of pm_isolate_run; a stream replacing the next child's. */
static bool in_child = false;
static int stream_fd = -1;

bool pm_isolate_in_child(void) { return in_child; }

void pm_isolate_stream(int fd) { stream_fd = fd; }

/* seconds, or PM_ISOLATE_CPU_SECONDS where it is a positive number. */
static double cpu_allowance(double seconds) {
  const char *v = getenv("PM_ISOLATE_CPU_SECONDS");
  char *end = NULL;
  const double s = v ? strtod(v, &end) : 0;
  return v && end != v && *end == '\0' && s > 0 && s < 1e9 ? s : seconds;
}

void pm_isolate_cpu_limit(double seconds) {
  seconds = cpu_allowance(seconds);
  struct rusage use;
  struct rlimit cpu;
  if (getrusage(RUSAGE_SELF, &use) != 0 || getrlimit(RLIMIT_CPU, &cpu) != 0)
    return;
  /* SIGXCPU, whose default ends the process, once the soft limit is
   * passed; the hard limit stays as it was.  The limit is in whole
   * seconds: the nearest to what was used plus the allowance, past what was
   * used (a fresh child allowed 1 s gets 1 s, not 2). */
  const double used =
      (double)use.ru_utime.tv_sec + (double)use.ru_stime.tv_sec +
      1e-6 * (double)(use.ru_utime.tv_usec + use.ru_stime.tv_usec);
  rlim_t s = (rlim_t)(used + seconds + 0.5);
  if (s < (rlim_t)used + 1) s = (rlim_t)used + 1;
  if (cpu.rlim_max != RLIM_INFINITY && s > cpu.rlim_max) s = cpu.rlim_max;
  cpu.rlim_cur = s;
  setrlimit(RLIMIT_CPU, &cpu);
}

/* Whether AddressSanitizer is in the build: its shadow memory takes
 * terabytes of address space, which an address-space limit would refuse. */
#if defined(__SANITIZE_ADDRESS__)
#define PM_ISOLATE_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PM_ISOLATE_ASAN 1
#endif
#endif

void pm_isolate_memory_limit(size_t bytes) {
#ifndef PM_ISOLATE_ASAN
  long pages = 0;
  struct rlimit as;
  FILE *f = fopen("/proc/self/statm", "r");
  if (!f) return;
  const bool got = fscanf(f, "%ld", &pages) == 1;
  fclose(f);
  if (!got || getrlimit(RLIMIT_AS, &as) != 0) return;
  rlim_t s = (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + (rlim_t)bytes;
  if (as.rlim_max != RLIM_INFINITY && s > as.rlim_max) s = as.rlim_max;
  as.rlim_cur = s;
  setrlimit(RLIMIT_AS, &as);
#else
  (void)bytes;
#endif
}

/* In the child, registered last so that it runs first: a library that
 * calls exit() must not run the parent's atexit handlers (HDF5's would
 * flush and close files the parent has open for writing). */
static void exit_by_library(int status, void *arg) {
  (void)status;
  (void)arg;
  _exit(EXIT_BY_LIBRARY);
}

/* The child: read, pass the outcome and the result, leave without running
 * anything of the parent's (atexit handlers, MPI, stream buffers). */
static void child(const pm_isolate_job *job, int fd) {
  in_child = true;
  signal(SIGINT, SIG_DFL); /* interrupted with the parent, not polled */
  signal(SIGTERM, SIG_DFL);
  signal(SIGPIPE, SIG_IGN); /* a parent gone: write fails, child leaves */
  /* A fault ends the child, whatever handler the parent set: a handler
   * that carries on (a test framework's, which runs the next test) would
   * run the parent's work in the child. */
  const int faults[] = {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL, SIGSYS};
  for (size_t k = 0; k < sizeof faults / sizeof *faults; k++)
    signal(faults[k], SIG_DFL);
#ifdef __linux__
  prctl(PR_SET_PDEATHSIG, SIGKILL);
#endif
  struct rlimit none = {0, 0};
  setrlimit(RLIMIT_CORE, &none); /* a library's fault leaves no core file */
  if (job->cpu_seconds > 0) pm_isolate_cpu_limit(job->cpu_seconds);
  /* One OpenMP thread: libgomp's pool of the parent's threads is not in
   * the child, and a region of more threads would wait on it for ever. */
  pm_omp_set_threads(1);
  on_exit(exit_by_library, NULL);
  pm_error_clear();
  const int32_t code = (int32_t)job->work(job->arg);
  const char *msg = code ? pm_error_message() : "";
  const uint32_t head[3] = {MARK_HEAD, (uint32_t)code, (uint32_t)strlen(msg)};
  const uint32_t end = MARK_END;
  bool ok = pm_isolate_put(fd, head, sizeof head) == PM_SUCCESS &&
            pm_isolate_put(fd, msg, head[2]) == PM_SUCCESS;
  if (ok && !code && job->put) ok = job->put(job->arg, fd) == PM_SUCCESS;
  ok = ok && pm_isolate_put(fd, &end, sizeof end) == PM_SUCCESS;
  _exit(ok ? 0 : 1);
}

static const char *signal_name(int sig) {
  switch (sig) {
  case SIGSEGV: return "SIGSEGV";
  case SIGBUS: return "SIGBUS";
  case SIGABRT: return "SIGABRT";
  case SIGFPE: return "SIGFPE";
  case SIGILL: return "SIGILL";
  case SIGKILL: return "SIGKILL";
  case SIGXCPU: return "SIGXCPU";
  case SIGSYS: return "SIGSYS";
  case SIGTRAP: return "SIGTRAP";
  case SIGINT: return "SIGINT";
  case SIGTERM: return "SIGTERM";
  default: return "a signal";
  }
}

/* The parent's side once the child was started: its outcome and result,
 * then its end.  *complete: the end mark arrived. */
static pm_err take(const pm_isolate_job *job, int fd, bool *complete) {
  uint32_t head[3], end = 0;
  *complete = false;
  PM_CALL(pm_isolate_get(fd, head, sizeof head));
  PM_CHECK(head[0] == MARK_HEAD && head[1] < PM_ERR_COUNT, PM_ERR_INTERNAL,
           "'%s': the child process reading it passed no outcome", job->path);
  if (head[1] != PM_SUCCESS) {
    char msg[1024];
    size_t n = head[2] < sizeof msg - 1 ? head[2] : sizeof msg - 1;
    PM_CALL(pm_isolate_get(fd, msg, n));
    msg[n] = '\0';
    *complete = true;
    return pm_error_set((pm_err)head[1], __FILE__, __LINE__, __func__, "%s",
                        msg);
  }
  /* A success carries no message: bytes there would be read as the
   * result's. */
  PM_CHECK(head[2] == 0, PM_ERR_INTERNAL,
           "'%s': the child process reading it passed a message with its "
           "success",
           job->path);
  if (job->get) PM_CALL(job->get(job->arg, fd));
  PM_CALL(pm_isolate_get(fd, &end, sizeof end));
  PM_CHECK(end == MARK_END, PM_ERR_INTERNAL,
           "'%s': the child process reading it passed a torn result",
           job->path);
  *complete = true;
  return PM_SUCCESS;
}

/* A result that take refused (short, torn, or a count it cannot hold):
 * the file, named, with the reason. */
static pm_err malformed(const pm_isolate_job *job) {
  char why[512];
  snprintf(why, sizeof why, "%s", pm_error_message());
  return PM_ERROR(job->code,
                  "%s: the child process reading it with %s passed a "
                  "malformed result (%s): the file is damaged or not %s",
                  job->path, job->library, why, job->what);
}

static void (*meanwhile)(void);

void pm_isolate_meanwhile(void (*task)(void)) { meanwhile = task; }

pm_err pm_isolate_run(const pm_isolate_job *job) {
  if (!pm_isolate_enabled()) return job->work(job->arg);
  if (stream_fd >= 0) {
    const int fd = stream_fd;
    bool complete = false;
    stream_fd = -1;
    const pm_err ret = take(job, fd, &complete);
    if (complete || ret == PM_ERR_INTERRUPTED) return ret;
    return ret ? malformed(job)
               : PM_ERROR(PM_ERR_INTERNAL,
                          "'%s': the child process reading it passed no "
                          "result",
                          job->path);
  }
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) return job->work(job->arg);
  fflush(NULL); /* nothing buffered is written twice */
  const pid_t pid = fork();
  if (pid < 0) { /* no process to spare: read here, unprotected */
    close(fds[0]);
    close(fds[1]);
    return job->work(job->arg);
  }
  if (pid == 0) {
    close(fds[0]);
    child(job, fds[1]);
  }
  close(fds[1]);
  if (meanwhile) {
    void (*task)(void) = meanwhile;
    meanwhile = NULL;
    task();
  }
  bool complete = false;
  pm_err ret = take(job, fds[0], &complete);
  close(fds[0]);
  if (pm_interrupt_signal() && !complete) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (complete) return ret;
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status), by = pm_interrupt_signal();
    if (sig == SIGINT || sig == SIGTERM || by)
      return PM_ERROR(PM_ERR_INTERRUPTED, "interrupted by %s while %s read %s",
                      pm_interrupt_name(by ? by : sig), job->library,
                      job->path);
    if (sig == SIGXCPU)
      return PM_ERROR(job->code,
                      "%s: %s used more than %g CPU seconds reading it "
                      "(SIGXCPU): the file is damaged or not %s",
                      job->path, job->library, cpu_allowance(job->cpu_seconds),
                      job->what);
    return PM_ERROR(job->code,
                    "%s: %s stopped with %s while reading it: the file is "
                    "damaged or not %s",
                    job->path, job->library, signal_name(sig), job->what);
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == EXIT_BY_LIBRARY)
    return PM_ERROR(job->code,
                    "%s: %s ended its process (exit) while reading it: the "
                    "file is damaged or not %s",
                    job->path, job->library, job->what);
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
    return PM_ERROR(job->code,
                    "%s: %s stopped (exit status %d) while reading it: the "
                    "file is damaged or not %s",
                    job->path, job->library, WEXITSTATUS(status), job->what);
  if (ret == PM_ERR_INTERRUPTED) return ret;
  return ret ? malformed(job)
             : PM_ERROR(PM_ERR_INTERNAL,
                        "'%s': the child process reading "
                        "it passed no result",
                        job->path);
}

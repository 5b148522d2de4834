/* fuzz_file: the files a reader under a fuzzer opens by name.  Each
 * process has one private folder in /dev/shm (in $TMPDIR, else /tmp,
 * where /dev/shm is missing), removed with everything in it at exit, so
 * an input written for a reader costs no disk and leaves nothing behind. */
#ifndef FUZZ_FILE_H
#define FUZZ_FILE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The private folder (created on first use; aborts when it cannot be). */
const char *fuzz_dir(void);

/* Write size bytes of data to the file at relative path name in the
 * private folder (its parent folders made) and return the full path, valid
 * until the next call.  Aborts when the file cannot be written. */
const char *fuzz_file(const char *name, const uint8_t *data, size_t size);

/* The full path of name in the private folder, without writing it. */
const char *fuzz_path(const char *name);

/* Remove everything in the private folder (the folder stays): between two
 * inputs, so that no file of one is read with the next. */
void fuzz_clear(void);

/* A results folder from one input: the folder's files joined by the
 * separator "\n--pm-fuzz-file--\n": results.h5 (the index), results/mesh.h5,
 * then frames 0, 1, ... (as many as follow, up to 8: the frames kept); the
 * mesh's point count a resumed run expects is the input's first 4 bytes
 * (little-endian).  Written to the private folder; false for an input of
 * fewer than 4 bytes.  *n_frames: the frames written (-2 or -1 when the
 * input stops before the mesh or the first frame). */
/* Before each input (data, size) of a harness whose readers run in a
 * child (pm_isolate.h): unless PM_ISOLATE_CPU_SECONDS is set, the child of
 * an HDF5 reader may use about a CPU second (the program's allowance is
 * 10: a damaged global heap loops HDF5 until then); and a child of the
 * fuzzer that dies with a sanitizer's report writes the input to
 * PM_FUZZ_CHILD_FINDINGS/child-PID (where set) instead of the fuzzer's own
 * crash report: the harness process refuses the file as the program does
 * and goes on. */
void fuzz_isolate(const uint8_t *data, size_t size);

bool fuzz_results_folder(const uint8_t *data, size_t size, long *n_points,
                         long *n_frames);

#endif

/* cadmorph core: status codes, the context every call takes first, logging and progress.
 *
 * Conventions of the whole library (every public header follows them):
 *  - Names: cm_<module>_<verb> for functions, cm_<noun> for types, CM_ for macros/enums.
 *    Functions of the API carry CM_API (export.h); nothing else is exported by libcadmorph.so.
 *  - Parameter order: context, inputs, outputs. Arrays: row-major, 0-based; documented with
 *    their shape, e.g. "xyz: #V x 3 double".
 *  - Return values: every fallible call returns cm_status: CM_OK (0), an error (< 0) or a
 *    warning (> 0: the result is complete, the message says what was odd). Test `s < 0` for
 *    failure. The message of the last error or warning is in the context
 *    (cm_context_message) until the next one; calls that succeed leave it alone. Functions
 *    that cannot fail return their value directly (counts, names, pointers into objects).
 *  - Ownership: cm_X_create(ctx, ..., &out) allocates, cm_X_destroy(&p) frees, accepts NULL
 *    and sets the pointer to NULL. On failure nothing leaks and outputs are NULL.
 *  - Pointer lifetimes: inputs are borrowed for the call and may be freed when it returns,
 *    unless the header says an object keeps them (the morpher keeps its cm_cad_model
 *    pointers: morph.h). Pointers a function returns into an object (names, arrays, info
 *    structs) stay valid until the object is destroyed or, where the header says so, until
 *    the next call on it; the caller never frees them. Strings returned without an object
 *    (cm_status_name, cm_version) are static.
 *  - Thread-safety: a context, and every object created with it, is used by one thread at a
 *    time; separate contexts and objects may be used from separate threads at once. Read-only
 *    objects (const parameters: models, locators, fitted RBFs, meshes) may be shared between
 *    threads. Internally calls run OpenMP leaf loops sized by cm_context_set_threads; the
 *    results do not depend on the thread count beyond round-off.
 *  - Process-wide effects (the only ones): the RBF factorisation and DM-FFD's SVD set
 *    OpenBLAS's thread count (openblas_set_num_threads) for their large calls and restore the
 *    caller's value before they return; two such calls in different threads at once may see
 *    each other's setting (speed only, not results). The first STEP read or write removes the printers of
 *    OpenCASCADE's default messenger (so the library never writes to stdout) and sets
 *    OpenCASCADE's translator parameters (Interface_Static: units, schema) under a lock;
 *    a program that uses OpenCASCADE itself sees both.
 *  - The library never prints, exits or aborts; the log callback decides what a user sees.
 */
#ifndef CADMORPH_CORE_H
#define CADMORPH_CORE_H

#include "cadmorph/export.h"

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum cm_status {
    CM_OK = 0,
    CM_WARNING = 1,            /* finished, but the message says what was odd */
    CM_ERR_NOMEM = -1,         /* allocation failed */
    CM_ERR_ARGUMENT = -2,      /* a caller error: NULL where data was required, bad option */
    CM_ERR_IO = -3,            /* a file could not be opened, read or written */
    CM_ERR_FORMAT = -4,        /* a file is malformed: the message has file and line/offset */
    CM_ERR_UNSUPPORTED = -5,   /* valid input that cadmorph does not handle */
    CM_ERR_MISMATCH = -6,      /* inputs that do not belong together (CAD vs mesh, G vs G') */
    CM_ERR_NUMERIC = -7,       /* singular or indefinite system, non-finite values */
    CM_ERR_CAD = -8,           /* OpenCASCADE failed */
    CM_ERR_INTERNAL = -9,      /* a bug or an exception from a dependency */
    CM_ERR_REJECTED = -10,     /* a result refused by a quality guard (inverted cells that no
                                  adaptive step avoids): exit code 3 in the CLI */
    CM_ERR_INTERRUPTED = -11,  /* the caller asked the call to stop (cm_context_interrupt);
                                  nothing was written and outputs are as on any error */
    CM_ERR_BUSY = -12          /* another process is writing the output (cm_output_lock):
                                  exit code 4 in the CLI */
} cm_status;

/* Short fixed name of a status, e.g. "format error". */
CM_API const char *cm_status_name(cm_status s);

/* True for errors that mean "the input is bad" (exit code 2 in the CLI). */
CM_API int cm_status_is_input_error(cm_status s);

typedef enum cm_log_level { CM_LOG_DEBUG = 0, CM_LOG_INFO = 1, CM_LOG_WARNING = 2 } cm_log_level;

typedef void (*cm_log_fn)(void *user, cm_log_level level, const char *message);
/* stage: short name ("sample", "solve"); done/total: units of work. */
typedef void (*cm_progress_fn)(void *user, const char *stage, double done, double total);

typedef struct cm_context cm_context;

CM_API cm_status cm_context_create(cm_context **ctx);
CM_API void cm_context_destroy(cm_context **ctx);

/* Message of the last error or warning set on this context ("" if none). */
CM_API const char *cm_context_message(const cm_context *ctx);
/* Forgets the message and an interrupt request not yet reported (cm_context_interrupt). */
CM_API void cm_context_clear(cm_context *ctx);

/* Threads for OpenMP leaf loops and BLAS; 0 = all available (default). Under an address-space
 * limit (ulimit -v) cm_context_threads returns no more than the free address space can give
 * stacks to (libgomp aborts the process when it cannot create a thread). */
CM_API void cm_context_set_threads(cm_context *ctx, int threads);
CM_API int cm_context_threads(const cm_context *ctx);

CM_API void cm_context_set_log(cm_context *ctx, cm_log_fn fn, void *user);
CM_API void cm_context_set_progress(cm_context *ctx, cm_progress_fn fn, void *user);

/* Asks the call running on ctx to stop: it returns CM_ERR_INTERRUPTED at its next progress
 * point (long loops report progress often enough to stop within a fraction of a second,
 * except inside one call of a dependency: a LAPACK factorisation, CHOLMOD, TetGen). Safe
 * from another thread, from a signal handler and from the progress callback itself. The
 * request stays until a call reports it or cm_context_clear drops it. */
CM_API void cm_context_interrupt(cm_context *ctx);

/* ---- for module code ---- */

/* Sets the context message (printf-style) and returns code, so that errors read
 * `return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s:%ld: expected ...", ...);`
 * The message is one line (control characters escaped as \n, \xHH) and a word longer than
 * 200 characters - a path - is shortened in its middle ("/head/.../name.vtu", the last
 * component kept whole up to 100 characters), so that what follows a long path stays. */
CM_API cm_status cm_error(cm_context *ctx, cm_status code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Puts "<prefix>: " (printf-style) in front of the context message and returns code, for a
 * caller that adds where an error happened: `return cm_error_prefix(ctx, s, "%s", path);`. */
CM_API cm_status cm_error_prefix(cm_context *ctx, cm_status code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

CM_API void cm_log(cm_context *ctx, cm_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Reports progress to the callback, then returns CM_ERR_INTERRUPTED (message "<stage>:
 * interrupted") when an interrupt was requested, consuming the request; CM_OK otherwise.
 * Long work calls it at points where it can stop cleanly and returns its error there. */
CM_API cm_status cm_progress(cm_context *ctx, const char *stage, double done, double total);

/* Threads for a leaf loop of n items that is worth parallelising above min_per_thread items
 * a thread: between 1 and the context's threads (0 there = all the machine has). */
CM_API int cm_context_threads_for(const cm_context *ctx, size_t n, size_t min_per_thread);

/* Length of the diagonal of a bounding box bb = {xmin, ymin, zmin, xmax, ymax, zmax}. */
CM_API double cm_bbox_diagonal(const double bb[6]);

/* Wall clock in seconds (monotonic), for stage timings in reports and benchmarks. */
CM_API double cm_wtime(void);

/* Bytes a single dense working set may take: half the machine's physical memory (the dense
 * RBF factor, DM-FFD's SVD), so that a request that cannot fit is refused with its size
 * instead of thrashing. 0 if the system does not say. */
CM_API double cm_memory_budget(void);

/* Bytes the system says are available now (Linux: MemAvailable, what can be allocated
 * without swapping), or cm_memory_budget() where it does not say: for sizing work that
 * may use what other processes leave free (a study's batches). */
CM_API double cm_memory_available(void);

/* ---- files ---- */

/* Every input is opened by the functions below (docs/DESIGN.md, "Reading input"): regular
 * files only, refused without blocking otherwise ("<path>: not a regular file (a FIFO)", a
 * directory, a device, ...). */

/* Reads a whole regular file into *data (NUL-terminated; *size excludes the NUL). The caller
 * frees *data. CM_ERR_IO with the path and the reason on failure. */
CM_API cm_status cm_file_read(cm_context *ctx, const char *path, char **data, size_t *size);

/* As cm_file_read for a text file whose lines are at most max_line bytes (the newline not
 * counted): a longer line or a NUL byte is CM_ERR_FORMAT "<path>:<line>: longer than K
 * bytes: not <what>" (what: e.g. "a design table"; NULL: "a text file"), found while reading,
 * so that a huge file without a newline costs about max_line bytes of memory. */
CM_API cm_status cm_file_read_text(cm_context *ctx, const char *path, size_t max_line,
                                   const char *what, char **data, size_t *size);

/* Opens a regular file for streaming reads ("rb"); the caller fcloses *f. CM_ERR_IO with the
 * path and the reason on failure. */
CM_API cm_status cm_file_open_read(cm_context *ctx, const char *path, FILE **f);

/* The same rule without a context, for looking at a file's first bytes: the stream, or NULL
 * with *why (if why is not NULL) the reason, e.g. "not a regular file (a FIFO)" (valid until
 * the thread's next call). */
CM_API FILE *cm_file_open_quiet(const char *path, const char **why);

/* Reads the next line of f into buf (cap >= 2 bytes; the newline is dropped, a '\r' kept) and
 * counts it in *line: 1 and its length in *len, 0 at the end of the file, or CM_ERR_FORMAT
 * for a line of cap bytes or more or a NUL byte ("<path>:<line>: longer than K bytes: not
 * <what>"), CM_ERR_IO for a read error. At most cap bytes are kept whatever the line's
 * length. */
CM_API int cm_file_read_line(cm_context *ctx, FILE *f, const char *path, const char *what,
                             long *line, char *buf, size_t cap, size_t *len);

/* Output through a temporary "<dir of path>/.cm-XXXXXX", renamed onto path by
 * cm_outfile_commit, so that a failed write never leaves a partial file. Write with
 * fprintf/fwrite to f. */
typedef struct cm_outfile {
    FILE *f;
    char *path;
    char *tmp;
} cm_outfile;

CM_API cm_status cm_outfile_open(cm_context *ctx, const char *path, cm_outfile *out);
/* Flushes, closes and renames; on any error removes the temporary file. */
CM_API cm_status cm_outfile_commit(cm_context *ctx, cm_outfile *out);
/* Closes and removes the temporary file (after an error). Safe to call twice. */
CM_API void cm_outfile_abort(cm_outfile *out);

/* Unlinks the temporary files of every cm_outfile still open in this process. Only
 * async-signal-safe calls: meant for a program's own SIGINT/SIGTERM/SIGHUP handler (the
 * library installs no handlers). */
CM_API void cm_outfile_unlink_all(void);

/* ---- outputs of several files (docs/DESIGN.md, "Command line
 * contract") ---- */

/* A directory built as a temporary sibling "<parent>/.cm-XXXXXX" (the parent is created)
 * and made visible by cm_outdir_commit in one step: a rename when the target is new or
 * empty, else an exchange of the two directories (Linux renameat2 RENAME_EXCHANGE) after
 * which the old one is removed. A file system that refuses the exchange gets two renames
 * (the old directory aside as ".cm-old-XXXXXX", then the new one into place; signals wait
 * for both). */
typedef struct cm_outdir {
    char *path; /* the target */
    char *tmp;  /* the temporary directory to write into */
} cm_outdir;

CM_API cm_status cm_outdir_open(cm_context *ctx, const char *path, cm_outdir *out);
CM_API cm_status cm_outdir_commit(cm_context *ctx, cm_outdir *out);
/* The temporary's files into the directory dir: when dir is new or empty (and the temporary
 * beside it), one rename of the temporary; else each name is first checked against the n
 * inputs by device and inode (CM_ERR_ARGUMENT, nothing moved, when one is an input), then
 * all are renamed as one group that signals do not interrupt. The temporary is removed in
 * any case. (For a temporary inside dir: cm_outdir_open of "dir/.cm".) */
CM_API cm_status cm_outdir_merge(cm_context *ctx, cm_outdir *out, const char *dir,
                                 const char *const *inputs, size_t n);
/* Removes the temporary directory and its content. Safe to call twice. */
CM_API void cm_outdir_abort(cm_outdir *out);

/* Commits n open outputs together: all flushed first (a write error aborts every one, none
 * renamed), then renamed as one group that signals do not interrupt; with from (else NULL),
 * the file from (written by another writer into a temporary directory) is renamed onto to
 * first, in the same group. */
CM_API cm_status cm_outfile_commit_all(cm_context *ctx, cm_outfile *outs, size_t n,
                                       const char *from, const char *to);

/* An exclusive lock (flock) on an output directory for the time of a write: CM_ERR_BUSY
 * "<dir>: another process is writing it" at once when another process holds it. *fd is the
 * lock, released by cm_output_unlock (or the process's end). */
CM_API cm_status cm_output_lock(cm_context *ctx, const char *dir, int *fd);
CM_API void cm_output_unlock(int *fd);

/* 1 when a and b both exist and are the same file (device and inode: hard links, symbolic
 * links and ".." paths included). */
CM_API int cm_same_file(const char *a, const char *b);

/* For a program's SIGINT/SIGTERM/SIGHUP handler, async-signal-safe: returns 1 when a group
 * of renames is under way (the signal is raised again when it is done: return from the
 * handler), else removes the live temporary directories and returns 0. */
CM_API int cm_output_signal(int sig);

/* True on a little-endian host (binary formats are written little-endian). */
CM_API int cm_host_little_endian(void);

#ifdef __cplusplus
}
#endif
#endif

/* Files that appear complete or not at all.
 *
 * The data goes to a new file with a unique name in the target's folder (created with O_EXCL, so
 * no other writer and no existing file is ever touched); dwvo_atomic_commit flushes it to disk
 * (fsync) and renames it over the target, which POSIX makes atomic within one file system. Any
 * failure, or dwvo_atomic_abort, removes the temporary file: the target is then exactly what it
 * was before (absent, or the previous good file). Readers never see a partial file.
 *
 * Errors come back as a dwv_result_t (DWV_ERROR_IO, DWV_ERROR_OUT_OF_MEMORY) with a message in the
 * caller's buffer naming the path and the system's reason (strerror). */
#ifndef DWV_OUTPUT_ATOMIC_FILE_H
#define DWV_OUTPUT_ATOMIC_FILE_H

#include <stddef.h>
#include <stdint.h>

#include <dwivedi.h>

typedef struct dwvo_atomic_file {
    int fd;         /* the temporary file, -1 when closed */
    int failed;     /* a write failed: commit refuses */
    char *target;   /* the path to replace */
    char *temp;     /* the temporary file's path (same folder) */
    char message[512]; /* the first write error */
} dwvo_atomic_file;

/* Creates the temporary file next to `target`. `target` must not be an existing directory or
 * other non-regular file. On failure nothing is left behind and *file needs no abort. */
dwv_result_t dwvo_atomic_open(dwvo_atomic_file *file, const char *target, char *message, size_t size);

/* Appends `size` bytes (retrying short writes and EINTR). 0 on success; on failure -1, the
 * file is marked failed and the reason kept for dwvo_atomic_commit's message. */
int dwvo_atomic_write(dwvo_atomic_file *file, const void *data, size_t size);
/* Writes at an absolute offset (pwrite), for formats that go back to fill in tables. */
int dwvo_atomic_pwrite(dwvo_atomic_file *file, const void *data, size_t size, uint64_t offset);

/* fsync, close, rename over the target, fsync the folder. On failure (including an earlier failed
 * write) the temporary file is removed and the target left as it was. Frees `file` either way. */
dwv_result_t dwvo_atomic_commit(dwvo_atomic_file *file, char *message, size_t size);
/* Closes and removes the temporary file; the target is untouched. Frees `file`. */
void dwvo_atomic_abort(dwvo_atomic_file *file);

/* Checks a caller's output path before any work: not NULL (the caller checks), not empty, shorter
 * than PATH_MAX, its folder exists and is a folder, and the target is not a directory. */
dwv_result_t dwvo_check_output_path(const char *target, char *message, size_t size);

#endif

/* Atomic replacement of files: see atomic_file.h. POSIX (open O_EXCL, fsync, rename). */
#define _POSIX_C_SOURCE 200809L

#include "atomic_file.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

static dwv_result_t io_fail(dwv_result_t result, char *message, size_t size, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static dwv_result_t io_fail(dwv_result_t result, char *message, size_t size, const char *format, ...)
{
    if (message && size > 0u) {
        va_list args;
        va_start(args, format);
        vsnprintf(message, size, format, args);
        va_end(args);
    }
    return result;
}

/* The folder part of `path` ("." when it has none), in a new string; NULL when out of memory. */
static char *folder_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return strdup(".");
    size_t length = slash == path ? 1u : (size_t)(slash - path); /* "/x" lives in "/" */
    char *folder = malloc(length + 1u);
    if (!folder) return NULL;
    memcpy(folder, path, length);
    folder[length] = '\0';
    return folder;
}

dwv_result_t dwvo_check_output_path(const char *target, char *message, size_t size)
{
    size_t length = strlen(target);
    if (length == 0u) return io_fail(DWV_ERROR_IO, message, size, "the output path is empty");
    /* Leave room for the temporary name's suffix. */
    if (length + 32u >= PATH_MAX)
        return io_fail(DWV_ERROR_IO, message, size, "the output path is %zu bytes long; at most %d are allowed",
                       length, PATH_MAX - 33);
    if (target[length - 1u] == '/')
        return io_fail(DWV_ERROR_IO, message, size, "'%s' names a folder, not a file", target);
    char *folder = folder_of(target);
    if (!folder) return io_fail(DWV_ERROR_OUT_OF_MEMORY, message, size, "no memory for a path");
    struct stat info;
    dwv_result_t result = DWV_SUCCESS;
    if (stat(folder, &info) != 0)
        result = io_fail(DWV_ERROR_IO, message, size, "cannot write '%s': folder '%s': %s", target, folder,
                         strerror(errno));
    else if (!S_ISDIR(info.st_mode))
        result = io_fail(DWV_ERROR_IO, message, size, "cannot write '%s': '%s' is not a folder", target, folder);
    else if (access(folder, W_OK | X_OK) != 0)
        result = io_fail(DWV_ERROR_IO, message, size, "cannot write '%s': folder '%s': %s", target, folder,
                         strerror(errno));
    else if (stat(target, &info) == 0 && !S_ISREG(info.st_mode))
        result = io_fail(DWV_ERROR_IO, message, size, "cannot write '%s': it exists and is %s", target,
                         S_ISDIR(info.st_mode) ? "a folder" : "not a regular file");
    free(folder);
    return result;
}

/* A name no other call of this process has used and unlikely for any other process: the pid, a
 * process-wide counter and the clock, mixed (splitmix64). O_EXCL makes a collision harmless. */
static uint64_t unique_bits(void)
{
    static atomic_uint_fast64_t counter;
    struct timespec now;
    timespec_get(&now, TIME_UTC);
    uint64_t z = ((uint64_t)getpid() << 32) ^ (uint64_t)now.tv_nsec ^ ((uint64_t)now.tv_sec << 20) ^
                 (atomic_fetch_add(&counter, 1u) * 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

dwv_result_t dwvo_atomic_open(dwvo_atomic_file *file, const char *target, char *message, size_t size)
{
    memset(file, 0, sizeof *file);
    file->fd = -1;
    dwv_result_t checked = dwvo_check_output_path(target, message, size);
    if (checked != DWV_SUCCESS) return checked;
    size_t length = strlen(target);
    const char *slash = strrchr(target, '/');
    size_t folder_length = slash ? (size_t)(slash - target) + 1u : 0u;
    file->target = strdup(target);
    file->temp = malloc(length + 32u);
    if (!file->target || !file->temp) {
        free(file->target);
        free(file->temp);
        return io_fail(DWV_ERROR_OUT_OF_MEMORY, message, size, "no memory for a path");
    }
    /* "<folder>/.<name>.<16 hex digits>.tmp": hidden, in the same folder (so rename is atomic). */
    for (int attempt = 0; attempt < 100; ++attempt) {
        snprintf(file->temp, length + 32u, "%.*s.%s.%016llx.tmp", (int)folder_length, target,
                 target + folder_length, (unsigned long long)unique_bits());
        file->fd = open(file->temp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (file->fd >= 0 || errno != EEXIST) break;
    }
    if (file->fd < 0) {
        int error = errno;
        dwv_result_t result = io_fail(DWV_ERROR_IO, message, size, "cannot create a temporary file for '%s' (%s): %s",
                                      target, file->temp, strerror(error));
        free(file->target);
        free(file->temp);
        file->target = file->temp = NULL;
        return result;
    }
    /* A replaced file keeps its permissions (a new one gets 0666 less the umask, as open made it). */
    struct stat info;
    if (stat(target, &info) == 0 && S_ISREG(info.st_mode)) (void)fchmod(file->fd, info.st_mode & 07777);
    return DWV_SUCCESS;
}

static int write_failed(dwvo_atomic_file *file, int error)
{
    if (!file->failed)
        snprintf(file->message, sizeof file->message, "writing '%s': %s", file->temp, strerror(error));
    file->failed = 1;
    return -1;
}

int dwvo_atomic_write(dwvo_atomic_file *file, const void *data, size_t size)
{
    if (file->failed) return -1;
    const unsigned char *bytes = data;
    while (size > 0u) {
        ssize_t written = write(file->fd, bytes, size);
        if (written < 0) {
            if (errno == EINTR) continue;
            return write_failed(file, errno);
        }
        if (written == 0) return write_failed(file, EIO);
        bytes += written;
        size -= (size_t)written;
    }
    return 0;
}

int dwvo_atomic_pwrite(dwvo_atomic_file *file, const void *data, size_t size, uint64_t offset)
{
    if (file->failed) return -1;
    const unsigned char *bytes = data;
    while (size > 0u) {
        if (offset > (uint64_t)INT64_MAX) return write_failed(file, EFBIG);
        ssize_t written = pwrite(file->fd, bytes, size, (off_t)offset);
        if (written < 0) {
            if (errno == EINTR) continue;
            return write_failed(file, errno);
        }
        if (written == 0) return write_failed(file, EIO);
        bytes += written;
        size -= (size_t)written;
        offset += (uint64_t)written;
    }
    return 0;
}

static void release(dwvo_atomic_file *file)
{
    free(file->target);
    free(file->temp);
    file->target = file->temp = NULL;
    file->fd = -1;
}

void dwvo_atomic_abort(dwvo_atomic_file *file)
{
    if (!file->temp) return;
    if (file->fd >= 0) close(file->fd);
    unlink(file->temp);
    release(file);
}

dwv_result_t dwvo_atomic_commit(dwvo_atomic_file *file, char *message, size_t size)
{
    if (!file->temp) return io_fail(DWV_ERROR_INTERNAL, message, size, "commit of a file that is not open");
    dwv_result_t result = DWV_SUCCESS;
    if (file->failed) {
        result = io_fail(DWV_ERROR_IO, message, size, "cannot write '%s': %s", file->target, file->message);
    } else if (fsync(file->fd) != 0) {
        result = io_fail(DWV_ERROR_IO, message, size, "cannot write '%s': flushing %s: %s", file->target,
                         file->temp, strerror(errno));
    }
    /* close reports deferred write errors of some file systems (NFS): it must succeed too. */
    int closed = close(file->fd);
    file->fd = -1;
    if (result == DWV_SUCCESS && closed != 0)
        result = io_fail(DWV_ERROR_IO, message, size, "cannot write '%s': closing %s: %s", file->target, file->temp,
                         strerror(errno));
    if (result == DWV_SUCCESS && rename(file->temp, file->target) != 0)
        result = io_fail(DWV_ERROR_IO, message, size, "cannot replace '%s' with %s: %s", file->target, file->temp,
                         strerror(errno));
    if (result != DWV_SUCCESS) {
        unlink(file->temp);
        release(file);
        return result;
    }
    /* Make the rename itself durable. The new file is in place whatever happens here, so a failure
     * to open or flush the folder is not reported as a failed write. */
    char *folder = folder_of(file->target);
    if (folder) {
        int fd = open(folder, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (fd >= 0) {
            (void)fsync(fd);
            close(fd);
        }
        free(folder);
    }
    release(file);
    return DWV_SUCCESS;
}

/* `mpirun -n N dwivedi bake ... --mpi` (docs/farm.md, "MPI"): the ranks bake sample ranges of one
 * bake, rank 0 merges them exactly (dwv_merge_partials) and writes the outputs. Built only where
 * CMake finds MPI; the library never links MPI, this file reaches it through capi only.
 *
 * Work is handed out by rank 0 on request (a worker asks when it starts and with each finished
 * range) rather than from a shared counter in an MPI window: rank 0 receives every range's sums
 * anyway, so it is in a message loop already, and a passive-target fetch-and-add progresses in
 * Open MPI only when the target enters MPI, which would tie the ranks to rank 0's loop as well.
 * Rank 0 bakes ranges of its own too: its bake runs on the library's threads while its main
 * thread answers the others.
 *
 * Every wait on another rank polls (MPI_Test, MPI_Iprobe) under --mpi-timeout, and a worker that
 * bakes reports every second, so a rank that is stopped or hung ends the job with a message
 * instead of a hang; a rank that fails reports its message to rank 0, which ends all ranks
 * (MPI_Abort, exit 1). Outputs are written only by rank 0 after the merge, under temporary names
 * renamed into place (cli_bake_write_outputs): no failure leaves a half-written output. */
#define _POSIX_C_SOURCE 200809L
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT */
#include <errno.h>
#include <stdarg.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <mpi.h>

#include "bake_cli.h"
#include "cli.h"
#include <dwivedi.h>

enum {
    TAG_READY = 1, /* worker -> 0: send me a range (first) */
    TAG_WORK,      /* 0 -> worker: u64 {first, count}; count 0: no more */
    TAG_CHUNK,     /* worker -> 0: u64 {first, count, bytes} of a baked range, then its bytes */
    TAG_BYTES,     /* worker -> 0: a block of the range's partial file */
    TAG_FAILED,    /* worker -> 0: the message of a failure */
    TAG_ALIVE      /* worker -> 0: still baking (every second) */
};

#define BLOCK_BYTES (16u << 20)  /* a transfer's block: files of any size in int-counted messages */
#define ALIVE_SECONDS 1.0
#define MESSAGE_BYTES 1024

static volatile sig_atomic_t interrupted = 0;

static void on_interrupt(int signal_number)
{
    (void)signal_number;
    interrupted = 1;
}

typedef struct job {
    int rank, ranks, local_ranks; /* local: the ranks on this node */
    double timeout;
    dwv_scene_t *scene;
    dwv_bake_options_t options;
    cli_bake_flags flags;
    char dir[4096];      /* rank 0: the private folder of the ranges' files ("" if none) */
    char **paths;        /* rank 0: the ranges' files, path_count of them */
    uint32_t path_count, path_capacity;
    /* rank 0's hand-out */
    uint64_t next_first, chunk;
    uint32_t *ranges_of;   /* ranges baked per rank */
    double *heard;         /* per rank: when it was last heard from */
    int *done;             /* per rank: it has been told that there is no more */
    double bytes_received, seconds_receiving;
    /* a worker's */
    MPI_Request alive;     /* the last "still baking" sent */
    double last_alive;
} job;

static double now(void)
{
    return MPI_Wtime();
}

static void pause_briefly(void)
{
    struct timespec t = {0, 1000000L};
    nanosleep(&t, NULL);
}

/* Removes rank 0's folder and the files in it. */
static void remove_files(job *j)
{
    for (uint32_t k = 0; k < j->path_count; ++k) {
        remove(j->paths[k]);
        free(j->paths[k]);
    }
    j->path_count = 0;
    free(j->paths);
    j->paths = NULL;
    if (j->dir[0]) rmdir(j->dir);
    j->dir[0] = '\0';
}

/* Ends every rank after a failure that this rank has reported: exit status `code`. */
static void end_all(job *j, int code)
#if defined(__GNUC__)
    __attribute__((noreturn))
#endif
    ;

static void end_all(job *j, int code)
{
    remove_files(j);
    fflush(stdout);
    fflush(stderr);
    /* A signal (mpirun ending the job, or Ctrl-C): this rank just ends; mpirun ends the others when
     * a rank exits without MPI_Finalize. Else MPI_Abort ends them all. */
    if (!interrupted) {
        /* the files are gone: mpirun's SIGTERM, which MPI_Abort brings here too, may now just end us */
        signal(SIGTERM, SIG_DFL);
        signal(SIGINT, SIG_DFL);
        MPI_Abort(MPI_COMM_WORLD, code);
    }
    _exit(code); /* MPI_Abort does not return; if it did, this rank still ends */
}

/* Waits for `request` to complete, at most the timeout; 0, or -1 after reporting what was awaited. */
static int wait_for(job *j, MPI_Request *request, const char *what, int peer)
{
    double start = now();
    for (;;) {
        int done = 0;
        MPI_Test(request, &done, MPI_STATUS_IGNORE);
        if (done) return 0;
        if (interrupted) return -1;
        if (now() - start > j->timeout) {
            char from[32] = "the other ranks";
            if (peer >= 0) snprintf(from, sizeof from, "rank %d", peer);
            fprintf(stderr, "dwivedi bake: rank %d of %d: no %s from %s in %g s (--mpi-timeout); ending all ranks\n",
                    j->rank, j->ranks, what, from, j->timeout);
            return -1; /* the caller ends all ranks, this request with them */
        }
        pause_briefly();
    }
}

static int send_to(job *j, const void *data, int count, MPI_Datatype type, int peer, int tag, const char *what)
{
    MPI_Request request;
    MPI_Isend(data, count, type, peer, tag, MPI_COMM_WORLD, &request);
    return wait_for(j, &request, what, peer);
}

static int receive_from(job *j, void *data, int count, MPI_Datatype type, int peer, int tag, const char *what)
{
    MPI_Request request;
    MPI_Irecv(data, count, type, peer, tag, MPI_COMM_WORLD, &request);
    return wait_for(j, &request, what, peer);
}

/* Threads per rank where neither the scene nor --threads says: the cores this rank is bound to,
 * or, unbound, the node's cores shared among the ranks on it (the image does not depend on it). */
static uint32_t default_threads(int local_ranks)
{
    long online = sysconf(_SC_NPROCESSORS_ONLN);
    cpu_set_t set;
    CPU_ZERO(&set);
    long bound = sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : online;
    if (online < 1) online = 1;
    long threads = bound > 0 && bound < online ? bound : online / (local_ranks > 0 ? local_ranks : 1);
    return threads < 1 ? 1u : threads > 1024 ? 1024u : (uint32_t)threads;
}

/* Bakes samples first .. first+count-1 into a partial file at `path`. While it bakes, `service`
 * runs every few milliseconds (rank 0 answers the others; a worker says it is alive). 0, or -1
 * after reporting into `message`. */
static int bake_range(job *j, uint64_t first, uint64_t count, const char *path, void (*service)(job *),
                      char *message, size_t message_size)
{
    dwv_bake_options_t o = j->options;
    o.sample_first = first;
    o.sample_count = count;
    dwv_bake_t *bake = NULL;
    dwv_image_t *image = NULL;
    int status = -1;
    if (dwv_bake_start(j->scene, &o, &bake) != DWV_SUCCESS) {
        snprintf(message, message_size, "%s", dwv_last_error_message());
        return -1;
    }
    for (int32_t finished = 0; !finished;) {
        /* rank 0 answers within 5 ms; a worker only reports that it lives */
        if (dwv_bake_wait(bake, j->rank == 0 ? 0.005 : 0.05, &finished) != DWV_SUCCESS) {
            snprintf(message, message_size, "%s", dwv_last_error_message());
            dwv_bake_cancel(bake);
            break;
        }
        if (interrupted) {
            /* mpirun ending the job sends SIGTERM and soon SIGKILL: the caller removes the files
             * and exits now, without waiting for the bake's threads to stop */
            dwv_bake_cancel(bake);
            snprintf(message, message_size, "cancelled; nothing written");
            return -1;
        }
        service(j);
    }
    dwv_result_t r = dwv_bake_finish(bake, &image);
    if (r == DWV_ERROR_CANCELLED) snprintf(message, message_size, "cancelled; nothing written");
    else if (r != DWV_SUCCESS || dwv_image_write_partial(image, path) != DWV_SUCCESS)
        snprintf(message, message_size, "samples %llu:%llu: %s", (unsigned long long)first, (unsigned long long)count,
                 dwv_last_error_message());
    else status = 0;
    dwv_image_release(image);
    dwv_bake_release(bake);
    return status;
}

/* ---- a worker (rank > 0) ------------------------------------------------------------------------ */

static void worker_service(job *j)
{
    static const char nothing = 0;
    if (now() - j->last_alive < ALIVE_SECONDS) return;
    int sent = 1;
    if (j->alive != MPI_REQUEST_NULL) MPI_Test(&j->alive, &sent, MPI_STATUS_IGNORE);
    if (!sent) return; /* rank 0 has not taken the last one yet: no pile of them */
    MPI_Isend(&nothing, 1, MPI_CHAR, 0, TAG_ALIVE, MPI_COMM_WORLD, &j->alive);
    j->last_alive = now();
}

/* Reports `message` to rank 0 (which ends all ranks), then waits to be ended. */
static void worker_fail(job *j, const char *message)
{
    char text[MESSAGE_BYTES];
    snprintf(text, sizeof text, "%s", message);
    if (send_to(j, text, (int)strlen(text) + 1, MPI_CHAR, 0, TAG_FAILED, "receipt of a failure") == 0) {
        double start = now();
        while (now() - start < j->timeout && !interrupted) pause_briefly();
        if (interrupted) end_all(j, CLI_FAILED); /* ended by rank 0, which has printed the message */
    }
    fprintf(stderr, "dwivedi bake: rank %d of %d: %s\n", j->rank, j->ranks, message);
    end_all(j, CLI_FAILED);
}

/* Sends the partial file at `path` (samples first:count) to rank 0 in blocks. */
static int send_file(job *j, const char *path, uint64_t first, uint64_t count, char *message, size_t message_size)
{
    FILE *in = fopen(path, "rb");
    long size = -1;
    if (!in || fseek(in, 0, SEEK_END) != 0 || (size = ftell(in)) < 0 || fseek(in, 0, SEEK_SET) != 0) {
        snprintf(message, message_size, "cannot read back %.900s: %s", path, strerror(errno));
        if (in) fclose(in);
        return -1;
    }
    char *block = malloc(BLOCK_BYTES);
    uint64_t head[3] = {first, count, (uint64_t)size};
    int status = -1;
    if (!block) snprintf(message, message_size, "out of memory");
    else if (send_to(j, head, 3, MPI_UINT64_T, 0, TAG_CHUNK, "receipt of a range") == 0) {
        status = 0;
        for (uint64_t sent = 0; sent < (uint64_t)size && status == 0;) {
            size_t n = (uint64_t)size - sent < BLOCK_BYTES ? (size_t)((uint64_t)size - sent) : BLOCK_BYTES;
            if (fread(block, 1, n, in) != n) {
                snprintf(message, message_size, "cannot read back %.900s", path);
                status = -1;
            } else if (send_to(j, block, (int)n, MPI_BYTE, 0, TAG_BYTES, "receipt of a range's bytes") != 0) {
                status = -2;
            }
            sent += n;
        }
    } else status = -2;
    free(block);
    fclose(in);
    return status;
}

static int run_worker(job *j)
{
    char path[4096], message[MESSAGE_BYTES];
    const char *tmp = getenv("TMPDIR");
    const char nothing = 0;
    if (send_to(j, &nothing, 1, MPI_CHAR, 0, TAG_READY, "answer") != 0) end_all(j, CLI_FAILED);
    for (;;) {
        uint64_t work[2];
        if (receive_from(j, work, 2, MPI_UINT64_T, 0, TAG_WORK, "range") != 0) end_all(j, CLI_FAILED);
        if (work[1] == 0u) break;
        /* The range's file lives only while it is written and sent (a killed rank leaves at most it). */
        snprintf(path, sizeof path, "%s/dwivedi-mpi-%ld-%llu.dwvpart", tmp && tmp[0] ? tmp : "/tmp", (long)getpid(),
                 (unsigned long long)work[0]);
        j->last_alive = now();
        if (bake_range(j, work[0], work[1], path, worker_service, message, sizeof message) != 0) {
            if (interrupted) {
                fprintf(stderr, "dwivedi bake: rank %d of %d: cancelled; nothing written\n", j->rank, j->ranks);
                end_all(j, 130);
            }
            worker_fail(j, message);
        }
        int sent = send_file(j, path, work[0], work[1], message, sizeof message);
        remove(path);
        if (sent == -1) worker_fail(j, message);
        if (sent != 0) end_all(j, interrupted ? 130 : CLI_FAILED);
    }
    /* rank 0 has taken every "still baking" before the last range (messages do not overtake) */
    if (j->alive != MPI_REQUEST_NULL && wait_for(j, &j->alive, "receipt of a report", 0) != 0)
        end_all(j, CLI_FAILED);
    return CLI_OK;
}

/* ---- rank 0 --------------------------------------------------------------------------------------- */

/* Reports "dwivedi bake: rank R of N: message; nothing written" and ends all ranks. */
static void root_fail(job *j, int rank, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4), noreturn))
#endif
    ;

static void root_fail(job *j, int rank, const char *format, ...)
{
    char text[MESSAGE_BYTES];
    va_list args;
    va_start(args, format);
    vsnprintf(text, sizeof text, format, args);
    va_end(args);
    fprintf(stderr, "dwivedi bake: rank %d of %d: %s; nothing written\n", rank, j->ranks, text);
    end_all(j, CLI_FAILED);
}

/* The next range to hand out: {first, count}; count 0 when all are out. */
static void next_range(job *j, uint64_t range[2])
{
    uint64_t left = j->options.samples - j->next_first;
    range[0] = j->next_first;
    range[1] = left < j->chunk ? left : j->chunk;
    j->next_first += range[1];
}

/* A file for the range from `first` that `rank` baked: the merge's messages name the rank at fault. */
static char *range_path(job *j, uint64_t first, int rank)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/samples-%llu-rank-%d.dwvpart", j->dir, (unsigned long long)first, rank);
    if (j->path_count == j->path_capacity) {
        uint32_t capacity = j->path_capacity ? 2u * j->path_capacity : 16u;
        char **grown = realloc(j->paths, capacity * sizeof *grown);
        if (!grown) return NULL;
        j->paths = grown;
        j->path_capacity = capacity;
    }
    char *copy = malloc(strlen(path) + 1u);
    if (!copy) return NULL;
    memcpy(copy, path, strlen(path) + 1u);
    j->paths[j->path_count++] = copy;
    return copy;
}

static void hand_out(job *j, int peer)
{
    uint64_t range[2];
    next_range(j, range);
    j->done[peer] = range[1] == 0u;
    j->heard[peer] = now();
    if (send_to(j, range, 2, MPI_UINT64_T, peer, TAG_WORK, "receipt of a range") != 0) end_all(j, CLI_FAILED);
}

/* Receives the next block of `peer`'s range into `block` (n bytes), or its failure's message. */
static void receive_block(job *j, int peer, char *block, int n)
{
    double start = now();
    for (;;) {
        int waiting = 0;
        MPI_Status status;
        MPI_Iprobe(peer, MPI_ANY_TAG, MPI_COMM_WORLD, &waiting, &status);
        if (waiting && status.MPI_TAG == TAG_BYTES) {
            MPI_Recv(block, n, MPI_BYTE, peer, TAG_BYTES, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            return;
        }
        if (waiting && status.MPI_TAG == TAG_FAILED) {
            char text[MESSAGE_BYTES];
            MPI_Recv(text, MESSAGE_BYTES, MPI_CHAR, peer, TAG_FAILED, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            text[MESSAGE_BYTES - 1] = '\0';
            root_fail(j, peer, "%s", text);
        }
        if (waiting) root_fail(j, 0, "unexpected message %d from rank %d within a range", status.MPI_TAG, peer);
        if (interrupted) end_all(j, 130);
        if (now() - start > j->timeout)
            root_fail(j, 0, "no bytes of a range from rank %d in %g s (--mpi-timeout)", peer, j->timeout);
        pause_briefly();
    }
}

/* Receives the range that `peer` announced with `head` {first, count, bytes} into rank 0's folder. */
static void receive_range(job *j, int peer, const uint64_t head[3])
{
    double start = now();
    char *path = range_path(j, head[0], peer);
    char *block = malloc(BLOCK_BYTES);
    FILE *out = path ? fopen(path, "wb") : NULL;
    if (!block || !out)
        root_fail(j, 0, "cannot store the range %llu:%llu of rank %d: %s", (unsigned long long)head[0],
                  (unsigned long long)head[1], peer, path ? strerror(errno) : "out of memory");
    for (uint64_t got = 0; got < head[2];) {
        int n = head[2] - got < BLOCK_BYTES ? (int)(head[2] - got) : (int)BLOCK_BYTES;
        receive_block(j, peer, block, n);
        if (fwrite(block, 1, (size_t)n, out) != (size_t)n)
            root_fail(j, 0, "cannot write %s: %s", path, strerror(errno));
        got += (uint64_t)n;
    }
    free(block);
    if (fclose(out) != 0) root_fail(j, 0, "cannot write %s: %s", path, strerror(errno));
    j->ranges_of[peer]++;
    j->bytes_received += (double)head[2];
    j->seconds_receiving += now() - start;
}

/* Answers every message waiting from the workers; checks that the busy ones are alive. */
static void root_service(job *j)
{
    for (;;) {
        int waiting = 0;
        MPI_Status status;
        MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &waiting, &status);
        if (!waiting) break;
        int peer = status.MPI_SOURCE;
        j->heard[peer] = now();
        if (status.MPI_TAG == TAG_READY || status.MPI_TAG == TAG_ALIVE) {
            char nothing;
            MPI_Recv(&nothing, 1, MPI_CHAR, peer, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            if (status.MPI_TAG == TAG_READY) hand_out(j, peer);
        } else if (status.MPI_TAG == TAG_CHUNK) {
            uint64_t head[3];
            MPI_Recv(head, 3, MPI_UINT64_T, peer, TAG_CHUNK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            receive_range(j, peer, head);
            hand_out(j, peer);
        } else if (status.MPI_TAG == TAG_FAILED) {
            char text[MESSAGE_BYTES];
            MPI_Recv(text, MESSAGE_BYTES, MPI_CHAR, peer, TAG_FAILED, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            text[MESSAGE_BYTES - 1] = '\0';
            root_fail(j, peer, "%s", text);
        } else {
            root_fail(j, 0, "unexpected message %d from rank %d", status.MPI_TAG, peer);
        }
    }
    for (int peer = 1; peer < j->ranks; ++peer) {
        if (!j->done[peer] && now() - j->heard[peer] > j->timeout)
            root_fail(j, 0, "rank %d has not been heard from in %g s (stopped or hung; --mpi-timeout)", peer,
                      j->timeout);
    }
}

/* Whether some worker has not yet been told that there is no more. */
static int workers_left(const job *j)
{
    for (int peer = 1; peer < j->ranks; ++peer)
        if (!j->done[peer]) return 1;
    return 0;
}

static int run_root(job *j, double start)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(j->dir, sizeof j->dir, "%s/dwivedi-mpi-XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
    if (!mkdtemp(j->dir)) {
        int error = errno;
        char tried[sizeof j->dir];
        memcpy(tried, j->dir, sizeof tried);
        j->dir[0] = '\0';
        root_fail(j, 0, "cannot make a folder %s for the ranges: %s", tried, strerror(error));
    }
    for (int peer = 1; peer < j->ranks; ++peer) j->heard[peer] = now();
    char message[MESSAGE_BYTES];
    /* rank 0 bakes too; between its ranges and while they bake, it answers the others */
    for (;;) {
        uint64_t range[2];
        next_range(j, range);
        if (range[1] == 0u) break;
        char *path = range_path(j, range[0], 0);
        if (!path) root_fail(j, 0, "out of memory");
        if (bake_range(j, range[0], range[1], path, root_service, message, sizeof message) != 0) {
            if (interrupted) {
                fprintf(stderr, "dwivedi bake: cancelled; nothing written\n");
                end_all(j, 130);
            }
            root_fail(j, 0, "%s", message);
        }
        j->ranges_of[0]++;
        root_service(j);
    }
    while (workers_left(j) || interrupted) {
        if (interrupted) {
            fprintf(stderr, "dwivedi bake: cancelled; nothing written\n");
            end_all(j, 130);
        }
        root_service(j);
        pause_briefly();
    }
    /* every worker has been told there is no more: merge, exactly as `dwivedi merge` would */
    double merge_start = now();
    dwv_image_t *image = NULL;
    if (dwv_merge_partials((const char *const *)j->paths, j->path_count, &image) != DWV_SUCCESS)
        root_fail(j, 0, "%s", dwv_last_error_message());
    if (cli_bake_write_outputs(j->flags.prefix, image, &j->options, &j->flags.display,
                               j->flags.scene_path ? j->flags.scene_path : "default", j->scene) != 0) {
        dwv_image_release(image);
        end_all(j, CLI_FAILED);
    }
    double merge_seconds = now() - merge_start;
    remove_files(j);
    dwv_bake_stats_t s = DWV_BAKE_STATS_INIT;
    dwv_image_stats(image, &s);
    dwv_image_release(image);
    printf("baked %ux%u, %llu spp on %d rank(s) of %u thread(s), %.2f s wall, estimated relative error %.3g%%\n",
           j->options.width, j->options.height, (unsigned long long)s.samples_per_pixel, j->ranks, j->options.threads,
           now() - start, 100.0 * s.estimated_relative_error);
    printf("mpi: ranges of %llu samples per rank:", (unsigned long long)j->chunk);
    for (int r = 0; r < j->ranks; ++r) printf(" %u", j->ranges_of[r]);
    printf("; received %.1f MB in %.3f s; merge and outputs %.3f s\n", j->bytes_received / 1e6, j->seconds_receiving,
           merge_seconds);
    printf("wrote %s.exr, %s.png, %s.json\n", j->flags.prefix, j->flags.prefix, j->flags.prefix);
    return CLI_OK;
}

/* Checks what --mpi cannot do; CLI_OK or CLI_USAGE after reporting. */
static int check_mpi_flags(cli_bake_flags *f, dwv_bake_options_t *o)
{
    if (f->chunk) return cli_usage_error("bake", "--mpi hands out the sample ranges itself: no --samples");
    if (f->budget)
        return cli_usage_error("bake",
                               "--mpi bakes exactly --spp samples: no --time or --error (docs/farm.md, \"MPI\")");
    if (o->samples == 0u) return cli_usage_error("bake", "--mpi: --spp must be at least 1");
    /* as for a chunk: the ranks bake the whole --spp, whatever the scene file's budgets say */
    o->time_limit = 0.0;
    o->target_error = 0.0;
    return CLI_OK;
}

int cli_mpi_bake(int argc, char **argv)
{
    double start = 0.0;
    job j;
    memset(&j, 0, sizeof j);
    if (MPI_Init(&argc, &argv) != MPI_SUCCESS) {
        fprintf(stderr, "dwivedi bake: --mpi: MPI_Init failed\n");
        return CLI_FAILED;
    }
    start = now();
    j.alive = MPI_REQUEST_NULL;
    MPI_Comm_rank(MPI_COMM_WORLD, &j.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &j.ranks);
    MPI_Comm node;
    j.local_ranks = 1;
    if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) == MPI_SUCCESS) {
        MPI_Comm_size(node, &j.local_ranks);
        MPI_Comm_free(&node);
    }
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, NULL);
    sigaction(SIGTERM, &action, NULL);

    /* every rank loads the scene; all agree before any work (the worst status wins) */
    int status = cli_bake_load(argc, argv, &j.flags, &j.options, &j.scene);
    j.timeout = j.flags.mpi_timeout;
    if (status == CLI_OK) status = check_mpi_flags(&j.flags, &j.options);
    if (status == CLI_OK && j.rank == 0 && cli_bake_check_outputs(j.flags.prefix, &j.flags.display) != 0)
        status = CLI_FAILED;
    if (status == CLI_OK && j.options.threads == 0u) j.options.threads = default_threads(j.local_ranks);
    int worst = status;
    {
        MPI_Request request;
        MPI_Iallreduce(&status, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD, &request);
        if (wait_for(&j, &request, "start (the scene loaded)", -1) != 0) end_all(&j, CLI_FAILED);
    }
    if (worst != CLI_OK) {
        if (status == CLI_OK && j.rank == 0)
            fprintf(stderr, "dwivedi bake: another rank could not start (its message is above); nothing written\n");
        dwv_scene_release(j.scene);
        MPI_Finalize();
        return worst;
    }
    j.chunk = j.flags.mpi_chunk;
    if (j.chunk == 0u) { /* two ranges per rank: some balance for ranks of unequal speed, little per-range cost */
        uint64_t ranges = 2u * (uint64_t)j.ranks;
        j.chunk = (j.options.samples + ranges - 1u) / ranges;
        if (j.chunk == 0u) j.chunk = 1u;
    }
    int code;
    if (j.rank == 0) {
        j.ranges_of = calloc((size_t)j.ranks, sizeof *j.ranges_of);
        j.heard = calloc((size_t)j.ranks, sizeof *j.heard);
        j.done = calloc((size_t)j.ranks, sizeof *j.done);
        if (!j.ranges_of || !j.heard || !j.done) root_fail(&j, 0, "out of memory");
        code = run_root(&j, start);
        free(j.ranges_of);
        free(j.heard);
        free(j.done);
    } else {
        code = run_worker(&j);
    }
    dwv_scene_release(j.scene);
    MPI_Finalize();
    return code;
}

// Fault injection for tests: an LD_PRELOAD library that counts the write
// operations a process makes on regular files and fails the Nth of them, as a
// full or failing disk would (docs/tools/fault_sweep.sh runs every command
// with N = 1 .. all; the Reliability.FaultSweepSample test runs a sample).
//
//   LD_PRELOAD=libvista_fault_inject.so  vista gen ...
//
// Environment (all optional):
//   VISTA_FAULT_AT=N          fail the Nth counted operation (1-based); unset
//                             or 0: count only
//   VISTA_FAULT_ERRNO=NAME    errno of the failure: ENOSPC (default), EIO,
//                             EDQUOT, EROFS, EFBIG
//   VISTA_FAULT_STICKY=1      fail every counted operation from the Nth on
//                             (a disk that stays full), not only the Nth
//   VISTA_FAULT_OPS=LIST      comma-separated operations to count (default
//                             all): create (open/fopen/creat of a file for
//                             writing), mkdir, write (write, pwrite, writev,
//                             pwritev), fsync (fsync, fdatasync), close (close
//                             of a file this process wrote), rename (rename,
//                             renameat, renameat2)
//   VISTA_FAULT_DIR=DIR       count only files under DIR (after symlinks);
//                             default: every regular file
//   VISTA_FAULT_COUNT_FILE=F  at exit, write to F the number of counted
//                             operations ("total N", then one line per kind)
//   VISTA_FAULT_LOG=F         when the fault fires, append "N OP PATH" to F
//
// What is counted: operations on regular files only (fstat), never on fds
// 0-2, pipes, sockets or terminals. Writes through stdio (fwrite, fclose)
// call glibc's internal write and are not seen; the streams of C++
// (std::ofstream) write with write()/writev() and are. Counting is per
// process (a forked child counts on from its parent's count and does not
// write the count file). Thread-safe: the counter is atomic, so with several
// writing threads which operation is the Nth depends on timing; the total
// does not.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

enum { kCreate, kMkdir, kWrite, kFsync, kClose, kRename, kOps };
static const char* const kOpNames[kOps] = {"create", "mkdir", "write", "fsync", "close", "rename"};

enum { kMaxFd = 65536 };

static long gAt = 0;
static int gErrno = ENOSPC;
static int gSticky = 0;
static unsigned gOps = (1u << kOps) - 1;
static char gDir[PATH_MAX];
static size_t gDirLen = 0;
static const char* gCountFile = NULL;
static const char* gLogFile = NULL;
static pid_t gPid = 0;
static atomic_long gCount = 0;
static atomic_long gPerOp[kOps];
static atomic_uchar gWritten[kMaxFd];  // fds written since they were opened
static _Thread_local int tInside = 0;  // this shim's own calls are not counted

#define REAL(name) ((__typeof__(&name))dlsym(RTLD_NEXT, #name))

static int parseErrno(const char* s) {
    static const struct {
        const char* name;
        int value;
    } kNames[] = {{"ENOSPC", ENOSPC}, {"EIO", EIO}, {"EDQUOT", EDQUOT}, {"EROFS", EROFS}, {"EFBIG", EFBIG}};
    for (size_t i = 0; i < sizeof(kNames) / sizeof(kNames[0]); ++i)
        if (strcmp(s, kNames[i].name) == 0) return kNames[i].value;
    const int n = atoi(s);
    return n > 0 ? n : ENOSPC;
}

__attribute__((constructor)) static void faultInit(void) {
    const char* s = getenv("VISTA_FAULT_AT");
    gAt = s ? atol(s) : 0;
    if ((s = getenv("VISTA_FAULT_ERRNO")) && *s) gErrno = parseErrno(s);
    gSticky = (s = getenv("VISTA_FAULT_STICKY")) && strcmp(s, "1") == 0;
    if ((s = getenv("VISTA_FAULT_OPS")) && *s) {
        gOps = 0;
        for (int k = 0; k < kOps; ++k) {
            const size_t n = strlen(kOpNames[k]);
            for (const char* p = s; (p = strstr(p, kOpNames[k])) != NULL; p += n)
                if ((p == s || p[-1] == ',') && (p[n] == ',' || p[n] == '\0')) gOps |= 1u << k;
        }
    }
    if ((s = getenv("VISTA_FAULT_DIR")) && *s && realpath(s, gDir)) gDirLen = strlen(gDir);
    gCountFile = getenv("VISTA_FAULT_COUNT_FILE");
    gLogFile = getenv("VISTA_FAULT_LOG");
    gPid = getpid();
}

__attribute__((destructor)) static void faultFini(void) {
    if (!gCountFile || !*gCountFile || getpid() != gPid) return;
    tInside = 1;
    FILE* f = fopen(gCountFile, "w");
    if (!f) return;
    fprintf(f, "total %ld\n", atomic_load(&gCount));
    for (int k = 0; k < kOps; ++k) fprintf(f, "%s %ld\n", kOpNames[k], atomic_load(&gPerOp[k]));
    fclose(f);
}

static int underDir(const char* abs) {
    if (gDirLen == 0) return 1;
    return strncmp(abs, gDir, gDirLen) == 0 && (abs[gDirLen] == '/' || abs[gDirLen] == '\0');
}

// The path of a regular file open as `fd` (into buf), or NULL when fd is not
// counted (0-2, not a regular file, outside VISTA_FAULT_DIR).
static const char* countedFd(int fd, char* buf, size_t size) {
    if (fd <= 2 || tInside) return NULL;
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return NULL;
    char link[64];
    snprintf(link, sizeof(link), "/proc/self/fd/%d", fd);
    const ssize_t n = readlink(link, buf, size - 1);
    if (n <= 0) return NULL;
    buf[n] = '\0';
    return underDir(buf) ? buf : NULL;
}

// `path` (relative to `dirfd`) made absolute into buf, or NULL when not counted.
static const char* countedPath(int dirfd, const char* path, char* buf, size_t size) {
    if (tInside || !path) return NULL;
    if (path[0] == '/') {
        snprintf(buf, size, "%s", path);
    } else {
        char base[PATH_MAX];
        if (dirfd == AT_FDCWD) {
            if (!getcwd(base, sizeof(base))) return NULL;
        } else {
            char link[64];
            snprintf(link, sizeof(link), "/proc/self/fd/%d", dirfd);
            const ssize_t n = readlink(link, base, sizeof(base) - 1);
            if (n <= 0) return NULL;
            base[n] = '\0';
        }
        snprintf(buf, size, "%s/%s", base, path);
    }
    return underDir(buf) ? buf : NULL;
}

// Counts one operation of kind `op` on `what`; 1 when it is to fail (errno set).
static int faultHere(int op, const char* what) {
    if (!(gOps & (1u << op))) return 0;
    const long n = atomic_fetch_add(&gCount, 1) + 1;
    atomic_fetch_add(&gPerOp[op], 1);
    if (gAt <= 0 || (gSticky ? n < gAt : n != gAt)) return 0;
    if (gLogFile && *gLogFile) {
        tInside = 1;
        FILE* f = fopen(gLogFile, "a");
        if (f) {
            fprintf(f, "%ld %s %s\n", n, kOpNames[op], what);
            fclose(f);
        }
        tInside = 0;
    }
    errno = gErrno;
    return 1;
}

static int writesFile(int flags) { return (flags & O_ACCMODE) != O_RDONLY || (flags & O_CREAT); }

static int faultFd(int op, int fd) {
    char buf[PATH_MAX];
    const char* p = countedFd(fd, buf, sizeof(buf));
    return p && faultHere(op, p);
}

static void markWritten(int fd, ssize_t n) {
    if (n > 0 && fd >= 0 && fd < kMaxFd) atomic_store(&gWritten[fd], 1);
}

ssize_t write(int fd, const void* b, size_t n) {
    if (faultFd(kWrite, fd)) return -1;
    const ssize_t r = REAL(write)(fd, b, n);
    markWritten(fd, r);
    return r;
}

ssize_t pwrite(int fd, const void* b, size_t n, off_t off) {
    if (faultFd(kWrite, fd)) return -1;
    const ssize_t r = REAL(pwrite)(fd, b, n, off);
    markWritten(fd, r);
    return r;
}

ssize_t pwrite64(int fd, const void* b, size_t n, off64_t off) {
    if (faultFd(kWrite, fd)) return -1;
    const ssize_t r = REAL(pwrite64)(fd, b, n, off);
    markWritten(fd, r);
    return r;
}

ssize_t writev(int fd, const struct iovec* v, int n) {
    if (faultFd(kWrite, fd)) return -1;
    const ssize_t r = REAL(writev)(fd, v, n);
    markWritten(fd, r);
    return r;
}

ssize_t pwritev(int fd, const struct iovec* v, int n, off_t off) {
    if (faultFd(kWrite, fd)) return -1;
    const ssize_t r = REAL(pwritev)(fd, v, n, off);
    markWritten(fd, r);
    return r;
}

int fsync(int fd) { return faultFd(kFsync, fd) ? -1 : REAL(fsync)(fd); }

int fdatasync(int fd) { return faultFd(kFsync, fd) ? -1 : REAL(fdatasync)(fd); }

int close(int fd) {
    if (fd >= 0 && fd < kMaxFd && atomic_exchange(&gWritten[fd], 0) && faultFd(kClose, fd)) {
        const int e = errno;
        REAL(close)(fd);  // the descriptor is released, as a failing close does
        errno = e;
        return -1;
    }
    return REAL(close)(fd);
}

static int faultPath(int op, int dirfd, const char* path) {
    char buf[2 * PATH_MAX + 2];
    const char* p = countedPath(dirfd, path, buf, sizeof(buf));
    return p && faultHere(op, p);
}

int rename(const char* from, const char* to) { return faultPath(kRename, AT_FDCWD, to) ? -1 : REAL(rename)(from, to); }

int renameat(int fromDir, const char* from, int toDir, const char* to) {
    return faultPath(kRename, toDir, to) ? -1 : REAL(renameat)(fromDir, from, toDir, to);
}

int renameat2(int fromDir, const char* from, int toDir, const char* to, unsigned flags) {
    return faultPath(kRename, toDir, to) ? -1 : REAL(renameat2)(fromDir, from, toDir, to, flags);
}

int mkdir(const char* path, mode_t mode) { return faultPath(kMkdir, AT_FDCWD, path) ? -1 : REAL(mkdir)(path, mode); }

int mkdirat(int dirfd, const char* path, mode_t mode) {
    return faultPath(kMkdir, dirfd, path) ? -1 : REAL(mkdirat)(dirfd, path, mode);
}

static mode_t modeArg(int flags, va_list ap) {
    return (flags & O_CREAT) || (flags & O_TMPFILE) == O_TMPFILE ? (mode_t)va_arg(ap, int) : 0;
}

int open(const char* path, int flags, ...) {
    va_list ap;
    va_start(ap, flags);
    const mode_t mode = modeArg(flags, ap);
    va_end(ap);
    if (writesFile(flags) && faultPath(kCreate, AT_FDCWD, path)) return -1;
    return REAL(open)(path, flags, mode);
}

int open64(const char* path, int flags, ...) {
    va_list ap;
    va_start(ap, flags);
    const mode_t mode = modeArg(flags, ap);
    va_end(ap);
    if (writesFile(flags) && faultPath(kCreate, AT_FDCWD, path)) return -1;
    return REAL(open64)(path, flags, mode);
}

int openat(int dirfd, const char* path, int flags, ...) {
    va_list ap;
    va_start(ap, flags);
    const mode_t mode = modeArg(flags, ap);
    va_end(ap);
    if (writesFile(flags) && faultPath(kCreate, dirfd, path)) return -1;
    return REAL(openat)(dirfd, path, flags, mode);
}

int creat(const char* path, mode_t mode) { return faultPath(kCreate, AT_FDCWD, path) ? -1 : REAL(creat)(path, mode); }

static int fopenWrites(const char* mode) { return mode && strpbrk(mode, "wa+") != NULL; }

FILE* fopen(const char* path, const char* mode) {
    if (fopenWrites(mode) && faultPath(kCreate, AT_FDCWD, path)) return NULL;
    return REAL(fopen)(path, mode);
}

FILE* fopen64(const char* path, const char* mode) {
    if (fopenWrites(mode) && faultPath(kCreate, AT_FDCWD, path)) return NULL;
    return REAL(fopen64)(path, mode);
}

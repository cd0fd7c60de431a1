/* A test-only LD_PRELOAD library that injects two faults into an unmodified process
 * (tests/xr_app/faults_test.sh):
 *
 *   disk full   DRAPE_FAULT_ENOSPC_MATCH=TEXT, DRAPE_FAULT_ENOSPC_AFTER=N: files whose path
 *               contains TEXT, opened with open/openat/fopen, accept N bytes in all (write,
 *               writev, fwrite); every later write fails with ENOSPC, and fclose/close of a
 *               file that saw the failure returns it again, as a full disk does.
 *   mic gone    DRAPE_FAULT_PCM_GONE_AFTER=N: ALSA's snd_pcm_readi returns -ENODEV once N
 *               frames were captured, as it does for a capture device unplugged mid-stream.
 *   device lost DRAPE_FAULT_VK_LOST_AFTER=N: vkWaitForFences returns VK_ERROR_DEVICE_LOST from
 *               its (N+1)-th call on.
 *
 * Each fault it injects is said once on stderr ("fault_inject: ..."), so the test's log shows it.
 * Its counters are not locked: in the tests each fault hits the calls of one thread (the writes
 * at the end of a run, the voice thread's captures, the frame loop's fence waits).
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>
#include <vulkan/vulkan.h>

enum { kMaxFd = 4096 };
static unsigned char tracked[kMaxFd]; /* 1: a matching file; 2: it has failed */
static long long budget = -1;         /* bytes the matching files still accept; -1: not read */
static int said_enospc = 0;

static void* next(const char* name) {
  return dlsym(RTLD_NEXT, name);
}

static int matches(const char* variable, const char* path) {
  const char* m = getenv(variable);
  return m && *m && path && strstr(path, m) != NULL;
}

static void track(int fd, const char* path) {
  if (fd < 0 || fd >= kMaxFd) return;
  tracked[fd] = matches("DRAPE_FAULT_ENOSPC_MATCH", path) ? 1 : 0;
}

static int is_tracked(int fd) {
  return fd >= 0 && fd < kMaxFd && tracked[fd] != 0;
}

/* How many of n bytes a write to fd may store; 0 with errno ENOSPC when none. */
static size_t allowed(int fd, size_t n) {
  if (!is_tracked(fd)) return n;
  if (budget < 0) {
    const char* a = getenv("DRAPE_FAULT_ENOSPC_AFTER");
    budget = a ? atoll(a) : 0;
  }
  size_t ok = (long long)n <= budget ? n : (size_t)budget;
  budget -= (long long)ok;
  if (ok < n) {
    tracked[fd] = 2;
    if (!said_enospc) {
      said_enospc = 1;
      fprintf(stderr, "fault_inject: ENOSPC: the disk is full (fd %d)\n", fd);
    }
  }
  return ok;
}

static int opened(int fd, const char* path) {
  track(fd, path);
  return fd;
}

static FILE* fopened(FILE* f, const char* path) {
  if (f) track(fileno(f), path);
  return f;
}

/* The mode argument of open and openat: there only when the flags create a file. */
#define CREATE_MODE(flags)               \
  mode_t mode = 0;                       \
  if ((flags) & (O_CREAT | O_TMPFILE)) { \
    va_list ap;                          \
    va_start(ap, flags);                 \
    mode = va_arg(ap, mode_t);           \
    va_end(ap);                          \
  }

typedef int (*OpenFn)(const char*, int, ...);
typedef FILE* (*FopenFn)(const char*, const char*);

int open(const char* path, int flags, ...) {
  CREATE_MODE(flags)
  return opened(((OpenFn)next("open"))(path, flags, mode), path);
}

int open64(const char* path, int flags, ...) {
  CREATE_MODE(flags)
  return opened(((OpenFn)next("open64"))(path, flags, mode), path);
}

int openat(int dir, const char* path, int flags, ...) {
  CREATE_MODE(flags)
  return opened(((int (*)(int, const char*, int, ...))next("openat"))(dir, path, flags, mode),
                path);
}

FILE* fopen(const char* path, const char* mode) {
  return fopened(((FopenFn)next("fopen"))(path, mode), path);
}

FILE* fopen64(const char* path, const char* mode) {
  return fopened(((FopenFn)next("fopen64"))(path, mode), path);
}

ssize_t write(int fd, const void* buf, size_t n) {
  static ssize_t (*real)(int, const void*, size_t);
  if (!real) real = (ssize_t(*)(int, const void*, size_t))next("write");
  const size_t ok = allowed(fd, n);
  if (ok == 0 && n > 0) {
    errno = ENOSPC;
    return -1;
  }
  return real(fd, buf, ok);
}

ssize_t writev(int fd, const struct iovec* iov, int count) {
  static ssize_t (*real)(int, const struct iovec*, int);
  if (!real) real = (ssize_t(*)(int, const struct iovec*, int))next("writev");
  if (!is_tracked(fd)) return real(fd, iov, count);
  /* Written piece by piece so that the budget cuts it where a full disk would. */
  ssize_t done = 0;
  for (int i = 0; i < count; ++i) {
    const ssize_t w = write(fd, iov[i].iov_base, iov[i].iov_len);
    if (w < 0) return done > 0 ? done : -1;
    done += w;
    if ((size_t)w < iov[i].iov_len) break;
  }
  return done;
}

size_t fwrite(const void* buf, size_t size, size_t items, FILE* f) {
  static size_t (*real)(const void*, size_t, size_t, FILE*);
  if (!real) real = (size_t(*)(const void*, size_t, size_t, FILE*))next("fwrite");
  const int fd = fileno(f);
  if (!is_tracked(fd) || size == 0) return real(buf, size, items, f);
  const size_t ok = allowed(fd, size * items) / size;
  const size_t w = ok > 0 ? real(buf, size, ok, f) : 0;
  if (w < items) errno = ENOSPC;
  return w;
}

/* snd_pcm_readi with ALSA's types spelled out (snd_pcm_sframes_t, snd_pcm_uframes_t). */
long snd_pcm_readi(void* pcm, void* buf, unsigned long frames) {
  static long (*real)(void*, void*, unsigned long);
  static long long captured = 0;
  static int said = 0;
  if (!real) real = (long (*)(void*, void*, unsigned long))next("snd_pcm_readi");
  const char* after = getenv("DRAPE_FAULT_PCM_GONE_AFTER");
  if (after && *after && captured >= atoll(after)) {
    if (!said) {
      said = 1;
      fprintf(stderr, "fault_inject: snd_pcm_readi: -ENODEV after %lld frames\n", captured);
    }
    return -ENODEV;
  }
  const long r = real(pcm, buf, frames);
  if (r > 0) captured += r;
  return r;
}

int close(int fd) {
  static int (*real)(int);
  if (!real) real = (int (*)(int))next("close");
  const int failed = fd >= 0 && fd < kMaxFd && tracked[fd] == 2;
  if (fd >= 0 && fd < kMaxFd) tracked[fd] = 0;
  const int r = real(fd);
  if (failed && r == 0) {
    errno = ENOSPC;
    return -1;
  }
  return r;
}

int fclose(FILE* f) {
  static int (*real)(FILE*);
  if (!real) real = (int (*)(FILE*))next("fclose");
  const int fd = fileno(f);
  const int failed = fd >= 0 && fd < kMaxFd && tracked[fd] == 2;
  if (fd >= 0 && fd < kMaxFd) tracked[fd] = 0;
  const int r = real(f);
  if (failed && r == 0) {
    errno = ENOSPC;
    return EOF;
  }
  return r;
}

VKAPI_ATTR VkResult VKAPI_CALL vkWaitForFences(VkDevice device, uint32_t count,
                                               const VkFence* fences, VkBool32 all,
                                               uint64_t timeout) {
  static PFN_vkWaitForFences real;
  static long long calls = 0;
  static int said = 0;
  if (!real) real = (PFN_vkWaitForFences)next("vkWaitForFences");
  const char* after = getenv("DRAPE_FAULT_VK_LOST_AFTER");
  if (after && *after && calls++ >= atoll(after)) {
    if (!said) {
      said = 1;
      fprintf(stderr, "fault_inject: vkWaitForFences: VK_ERROR_DEVICE_LOST (call %lld)\n", calls);
    }
    return VK_ERROR_DEVICE_LOST;
  }
  return real(device, count, fences, all, timeout);
}

/*
 * xstate_shim: lets Debian 12's User-Mode Linux (6.1) run on hosts whose
 * XSAVE area is larger than the fixed buffer UML was built with.
 *
 * UML restores a process's FP state with PTRACE_SETREGSET(NT_X86_XSTATE)
 * from a buffer of a fixed size (2696 bytes). The host kernel accepts only a
 * buffer of its full XSAVE size (11008 bytes with AMX) and answers anything
 * shorter with EFAULT, so UML panics at its first process. Linux 6.13 sizes
 * the buffer from the host; 6.1 does not.
 *
 * Loaded with LD_PRELOAD into linux.uml, this wraps ptrace(): a short
 * SETREGSET(NT_X86_XSTATE) becomes a full-size one made of the tracee's
 * current state (PTRACE_GETREGSET) with UML's bytes laid over its start. The
 * state UML knows (x87, SSE, AVX, AVX-512, PKRU) is UML's; the rest (AMX
 * tiles, which no guest process can enable) stays the tracee's own. A buffer
 * that already holds the host's full area passes through unchanged.
 *
 * If XSTATE_SHIM_LOG names a file, the first widened call appends one line
 * "xstate shim: <uml bytes> -> <host bytes> bytes" to it.
 *
 * UML issues its ptrace calls from one host thread, so the shim's buffer
 * and the cached size need no lock.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <dlfcn.h>
#include <elf.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ptrace.h>
#include <sys/uio.h>
#include <unistd.h>

#ifndef NT_X86_XSTATE
#define NT_X86_XSTATE 0x202
#endif

/* Far beyond any x86 XSAVE area so far (11008 bytes with AMX). */
#define XSTATE_MAX (64 * 1024)

typedef long ptrace_fn(int, pid_t, void *, void *);

static unsigned char full[XSTATE_MAX] __attribute__((aligned(64)));
static int logged;

static ptrace_fn *real_ptrace(void)
{
    static ptrace_fn *fn;
    if (!fn)
        fn = (ptrace_fn *)dlsym(RTLD_NEXT, "ptrace");
    return fn;
}

static void log_once(size_t from, size_t to)
{
    const char *path = getenv("XSTATE_SHIM_LOG");
    if (logged || !path || !*path)
        return;
    logged = 1;
    int fd = open(path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0)
        return;
    char line[80];
    int n = snprintf(line, sizeof line, "xstate shim: %zu -> %zu bytes\n", from, to);
    if (n > 0 && write(fd, line, (size_t)n) < 0)
        n = 0;
    close(fd);
}

/* SETREGSET(NT_X86_XSTATE) with a buffer that may be shorter than the
 * host's area: widen it as the header explains. */
static long set_xstate(ptrace_fn *sys, pid_t pid, struct iovec *uml)
{
    struct iovec cur = { full, sizeof full };
    if (sys(PTRACE_GETREGSET, pid, (void *)(long)NT_X86_XSTATE, &cur) == -1)
        return -1;
    if (uml->iov_len >= cur.iov_len) /* the host's area fits: as it was */
        return sys(PTRACE_SETREGSET, pid, (void *)(long)NT_X86_XSTATE, uml);
    memcpy(full, uml->iov_base, uml->iov_len);
    log_once(uml->iov_len, cur.iov_len);
    return sys(PTRACE_SETREGSET, pid, (void *)(long)NT_X86_XSTATE, &cur);
}

long ptrace(enum __ptrace_request request, ...)
{
    va_list ap;
    va_start(ap, request);
    pid_t pid = va_arg(ap, pid_t);
    void *addr = va_arg(ap, void *);
    void *data = va_arg(ap, void *);
    va_end(ap);

    ptrace_fn *sys = real_ptrace();
    if (!sys) {
        errno = ENOSYS;
        return -1;
    }
    if (request == PTRACE_SETREGSET && (long)addr == NT_X86_XSTATE && data)
        return set_xstate(sys, pid, data);
    return sys((int)request, pid, addr, data);
}

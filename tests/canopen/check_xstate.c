/*
 * The xstate shim on the host, against a real traced process: a buffer
 * shorter than the host's XSAVE area (what Debian 12's UML sends on an AMX
 * host) is refused by the kernel, and accepted through the shim with the
 * register state the short buffer does not cover left as it was. The shim
 * is linked into this program, so its ptrace() is the one called here;
 * raw syscalls reach the kernel without it.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <check.h>
#include <cpuid.h>
#include <elf.h>
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/ptrace.h>
#include <sys/syscall.h>
#include <sys/uio.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../common/check_run.h"

#ifndef NT_X86_XSTATE
#define NT_X86_XSTATE 0x202
#endif

enum { LEGACY_HEADER = 576, XMM0_AT = 160, XSTATE_MAX = 64 * 1024 };

static const long marker = 0x1234567890abcdefL;
static unsigned char cur[XSTATE_MAX] __attribute__((aligned(64)));

static int has_avx512(void)
{
    unsigned a, b, c, d;
    return __get_cpuid_count(7, 0, &a, &b, &c, &d) && (b & (1u << 16));
}

static void fill(unsigned char *p, size_t n, unsigned seed)
{
    for (size_t i = 0; i < n; i++)
        p[i] = (unsigned char)(seed * 31u + i * 7u + 1u);
}

/* The child keeps ymm1 (and zmm16 with AVX-512) loaded with known patterns,
 * stops, and when resumed reports xmm0, ymm1 and zmm16 without any code
 * between that could touch them: one asm block. */
struct regs { unsigned char xmm0[16], ymm1[32], zmm16[64]; };

static struct regs expect_after(void)
{
    struct regs r;
    fill(r.xmm0, sizeof r.xmm0, 3);
    fill(r.ymm1, sizeof r.ymm1, 5);
    fill(r.zmm16, sizeof r.zmm16, 7);
    return r;
}

static int same(const struct regs *a, const struct regs *b, int avx512)
{
    return !memcmp(a->xmm0, b->xmm0, 16) && !memcmp(a->ymm1, b->ymm1, 32)
           && (!avx512 || !memcmp(a->zmm16, b->zmm16, 64));
}

__attribute__((target("avx512f"))) static void child_avx512(void)
{
    struct regs in = expect_after(), out;
    memset(&out, 0, sizeof out);
    long pid = getpid();
    ptrace(PTRACE_TRACEME, 0, 0, 0);
    __asm__ volatile(
        "vmovdqu %2, %%ymm1\n\t"
        "vmovdqu64 %3, %%zmm16\n\t"
        "mov $62, %%eax\n\t" /* kill(pid, SIGSTOP) */
        "mov %4, %%rdi\n\t"
        "mov $19, %%esi\n\t"
        "syscall\n\t"
        "vmovdqu %%xmm0, %0\n\t"
        "vmovdqu %%ymm1, %1\n\t"
        "vmovdqu64 %%zmm16, %5\n\t"
        : "=m"(out.xmm0), "=m"(out.ymm1), "+m"(in.ymm1), "+m"(in.zmm16),
          "+r"(pid), "=m"(out.zmm16)
        :
        : "rax", "rdi", "rsi", "rcx", "r11", "xmm0", "xmm1", "xmm16", "memory");
    _exit(same(&out, &in, 1) ? 0 : 1);
}

__attribute__((target("avx"))) static void child_avx(void)
{
    struct regs in = expect_after(), out;
    memset(&out, 0, sizeof out);
    long pid = getpid();
    ptrace(PTRACE_TRACEME, 0, 0, 0);
    __asm__ volatile(
        "vmovdqu %2, %%ymm1\n\t"
        "mov $62, %%eax\n\t"
        "mov %3, %%rdi\n\t"
        "mov $19, %%esi\n\t"
        "syscall\n\t"
        "vmovdqu %%xmm0, %0\n\t"
        "vmovdqu %%ymm1, %1\n\t"
        : "=m"(out.xmm0), "=m"(out.ymm1), "+m"(in.ymm1), "+r"(pid)
        :
        : "rax", "rdi", "rsi", "rcx", "r11", "xmm0", "xmm1", "memory");
    _exit(same(&out, &in, 0) ? 0 : 1);
}

/* A stopped traced child, and the size of the host's XSAVE area. */
static pid_t start_child(size_t *full)
{
    pid_t pid = fork();
    ck_assert_int_ge(pid, 0);
    if (pid == 0) {
        if (has_avx512())
            child_avx512();
        child_avx();
    }
    int st;
    ck_assert_int_eq(waitpid(pid, &st, 0), pid);
    ck_assert(WIFSTOPPED(st));
    struct iovec io = { cur, sizeof cur };
    ck_assert_int_eq(syscall(SYS_ptrace, PTRACE_GETREGSET, pid, NT_X86_XSTATE, &io), 0);
    *full = io.iov_len;
    ck_assert_uint_gt(*full, LEGACY_HEADER);
    return pid;
}

static int finish_child(pid_t pid)
{
    int st;
    ck_assert_int_eq(syscall(SYS_ptrace, PTRACE_CONT, pid, 0, 0), 0);
    ck_assert_int_eq(waitpid(pid, &st, 0), pid);
    ck_assert(WIFEXITED(st));
    return WEXITSTATUS(st);
}

START_TEST(kernel_refuses_short_buffer)
{
    size_t full;
    pid_t pid = start_child(&full);
    struct iovec io = { cur, LEGACY_HEADER };
    errno = 0;
    ck_assert_int_eq(syscall(SYS_ptrace, PTRACE_SETREGSET, pid, NT_X86_XSTATE, &io), -1);
    ck_assert_int_eq(errno, EFAULT);
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
}
END_TEST

/* UML's bytes land (xmm0 changed), the state past them stays (ymm1's upper
 * half in the AVX area, zmm16 in the AVX-512 area). */
START_TEST(short_buffer_widened)
{
    size_t full;
    pid_t pid = start_child(&full);
    struct regs want = expect_after();
    static unsigned char uml[LEGACY_HEADER] __attribute__((aligned(64)));
    memcpy(uml, cur, sizeof uml);
    memcpy(uml + XMM0_AT, want.xmm0, 16);
    struct iovec io = { uml, sizeof uml };
    ck_assert_int_eq(ptrace(PTRACE_SETREGSET, pid, (void *)NT_X86_XSTATE, &io), 0);
    ck_assert_int_eq(finish_child(pid), 0);
}
END_TEST

START_TEST(full_buffer_passes_through)
{
    size_t full;
    pid_t pid = start_child(&full);
    struct regs want = expect_after();
    memcpy(cur + XMM0_AT, want.xmm0, 16);
    struct iovec io = { cur, full };
    ck_assert_int_eq(ptrace(PTRACE_SETREGSET, pid, (void *)NT_X86_XSTATE, &io), 0);
    ck_assert_int_eq(finish_child(pid), 0);
}
END_TEST

/* Without any write the child must see its own registers; with a wrong
 * xmm0 it must report it: the check in the child can fail. */
START_TEST(child_detects_a_wrong_register)
{
    size_t full;
    pid_t pid = start_child(&full);
    memset(cur + XMM0_AT, 0xA5, 16);
    struct iovec io = { cur, full };
    ck_assert_int_eq(ptrace(PTRACE_SETREGSET, pid, (void *)NT_X86_XSTATE, &io), 0);
    ck_assert_int_eq(finish_child(pid), 1);
}
END_TEST

START_TEST(other_requests_untouched)
{
    size_t full;
    pid_t pid = start_child(&full);
    errno = 0;
    long word = ptrace(PTRACE_PEEKDATA, pid, (void *)&marker, 0);
    ck_assert_int_eq(errno, 0);
    ck_assert_int_eq(word, marker);
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("xstate_shim");
    TCase *tc = tcase_create("host");
    tcase_add_test(tc, kernel_refuses_short_buffer);
    tcase_add_test(tc, short_buffer_widened);
    tcase_add_test(tc, full_buffer_passes_through);
    tcase_add_test(tc, child_detects_a_wrong_register);
    tcase_add_test(tc, other_requests_untouched);
    suite_add_tcase(s, tc);
    return check_run(s);
}

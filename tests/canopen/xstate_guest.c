/*
 * Run inside the bus test's guest kernel: several processes keep every
 * vector register live (zmm0-31 and k1-k7 with AVX-512, else ymm0-15 or
 * xmm0-15) with patterns of their own while they yield to each other
 * thousands of times, then check that nothing changed. Under User-Mode Linux each yield is a
 * context switch that restores the FP state through ptrace, the path the
 * xstate shim widens on AMX hosts.
 *   xstate_guest [processes [yields]]      prints PASS:/FAIL: lines
 *   xstate_guest --xsave-size              the host's XSAVE area in bytes
 */
#include <cpuid.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

enum { ZREGS = 32, YREGS = 16 };

static int has_avx512(void)
{
    unsigned a, b, c, d;
    return __get_cpuid_count(7, 0, &a, &b, &c, &d) && (b & (1u << 16));
}

static void fill(unsigned char *p, size_t n, unsigned seed)
{
    for (size_t i = 0; i < n; i++)
        p[i] = (unsigned char)((seed + 1u) * 131u + i * 17u + (i >> 8));
}

/* Load every register, yield `yields` times with raw syscalls (so no code
 * of ours or libc's runs between), store them back. */
#define YIELD_LOOP \
    "1:\n\t" \
    "mov $24, %%eax\n\t" /* sched_yield */ \
    "syscall\n\t" \
    "dec %%rdx\n\t" \
    "jnz 1b\n\t"

#define Z(i) "vmovdqu64 " #i "*64(%0), %%zmm" #i "\n\t"
#define ZS(i) "vmovdqu64 %%zmm" #i ", " #i "*64(%1)\n\t"
#define K(i) "kmovq " #i "*8(%2), %%k" #i "\n\t"
#define KS(i) "kmovq %%k" #i ", " #i "*8(%3)\n\t"

__attribute__((target("avx512f,avx512bw"))) static void
run_avx512(const unsigned char *in, unsigned char *out, const unsigned char *kin,
           unsigned char *kout, long yields)
{
    __asm__ volatile(
        Z(0) Z(1) Z(2) Z(3) Z(4) Z(5) Z(6) Z(7) Z(8) Z(9) Z(10) Z(11) Z(12) Z(13) Z(14) Z(15)
        Z(16) Z(17) Z(18) Z(19) Z(20) Z(21) Z(22) Z(23) Z(24) Z(25) Z(26) Z(27) Z(28) Z(29)
        Z(30) Z(31) K(1) K(2) K(3) K(4) K(5) K(6) K(7)
        YIELD_LOOP
        ZS(0) ZS(1) ZS(2) ZS(3) ZS(4) ZS(5) ZS(6) ZS(7) ZS(8) ZS(9) ZS(10) ZS(11) ZS(12)
        ZS(13) ZS(14) ZS(15) ZS(16) ZS(17) ZS(18) ZS(19) ZS(20) ZS(21) ZS(22) ZS(23)
        ZS(24) ZS(25) ZS(26) ZS(27) ZS(28) ZS(29) ZS(30) ZS(31)
        KS(1) KS(2) KS(3) KS(4) KS(5) KS(6) KS(7)
        : "+r"(in), "+r"(out), "+r"(kin), "+r"(kout), "+d"(yields)
        :
        : "rax", "rcx", "r11", "memory",
          "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7", "xmm8", "xmm9",
          "xmm10", "xmm11", "xmm12", "xmm13", "xmm14", "xmm15", "xmm16", "xmm17", "xmm18",
          "xmm19", "xmm20", "xmm21", "xmm22", "xmm23", "xmm24", "xmm25", "xmm26", "xmm27",
          "xmm28", "xmm29", "xmm30", "xmm31", "k1", "k2", "k3", "k4", "k5", "k6", "k7");
}

#define Y(i) "vmovdqu " #i "*32(%0), %%ymm" #i "\n\t"
#define YS(i) "vmovdqu %%ymm" #i ", " #i "*32(%1)\n\t"

__attribute__((target("avx"))) static void
run_avx(const unsigned char *in, unsigned char *out, long yields)
{
    __asm__ volatile(
        Y(0) Y(1) Y(2) Y(3) Y(4) Y(5) Y(6) Y(7) Y(8) Y(9) Y(10) Y(11) Y(12) Y(13) Y(14) Y(15)
        YIELD_LOOP
        YS(0) YS(1) YS(2) YS(3) YS(4) YS(5) YS(6) YS(7) YS(8) YS(9) YS(10) YS(11) YS(12)
        YS(13) YS(14) YS(15)
        : "+r"(in), "+r"(out), "+d"(yields)
        :
        : "rax", "rcx", "r11", "memory", "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5",
          "xmm6", "xmm7", "xmm8", "xmm9", "xmm10", "xmm11", "xmm12", "xmm13", "xmm14",
          "xmm15");
}

#define X(i) "movdqu " #i "*16(%0), %%xmm" #i "\n\t"
#define XS(i) "movdqu %%xmm" #i ", " #i "*16(%1)\n\t"

static void run_sse(const unsigned char *in, unsigned char *out, long yields)
{
    __asm__ volatile(
        X(0) X(1) X(2) X(3) X(4) X(5) X(6) X(7) X(8) X(9) X(10) X(11) X(12) X(13) X(14) X(15)
        YIELD_LOOP
        XS(0) XS(1) XS(2) XS(3) XS(4) XS(5) XS(6) XS(7) XS(8) XS(9) XS(10) XS(11) XS(12)
        XS(13) XS(14) XS(15)
        : "+r"(in), "+r"(out), "+d"(yields)
        :
        : "rax", "rcx", "r11", "memory", "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5",
          "xmm6", "xmm7", "xmm8", "xmm9", "xmm10", "xmm11", "xmm12", "xmm13", "xmm14",
          "xmm15");
}

static int has_avx(void)
{
    unsigned a, b, c, d;
    return __get_cpuid(1, &a, &b, &c, &d) && (c & (1u << 28)) && (c & (1u << 27));
}

/* One process's run: 0 when every register came back as loaded. */
static int one(unsigned seed, int avx512, int avx, long yields)
{
    static unsigned char in[ZREGS * 64], out[ZREGS * 64], kin[8 * 8], kout[8 * 8];
    size_t n = avx512 ? sizeof in : avx ? YREGS * 32 : YREGS * 16;
    fill(in, n, seed);
    fill(kin, sizeof kin, seed + 100);
    memset(out, 0, sizeof out);
    memset(kout, 0, sizeof kout);
    if (avx512)
        run_avx512(in, out, kin, kout, yields);
    else if (avx)
        run_avx(in, out, yields);
    else
        run_sse(in, out, yields);
    if (memcmp(in, out, n) != 0)
        return 1;
    /* mask registers are 64 bits wide with AVX512BW; k0 is not loaded */
    return avx512 && memcmp(kin + 8, kout + 8, 7 * 8) != 0;
}

int main(int argc, char **argv)
{
    if (argc == 2 && !strcmp(argv[1], "--xsave-size")) {
        unsigned a, b, c, d;
        if (!__get_cpuid_count(0xd, 0, &a, &b, &c, &d))
            return 1;
        printf("%u\n", b); /* EBX: the area for the features XCR0 enables */
        return 0;
    }
    int procs = argc > 1 ? atoi(argv[1]) : 4;
    long yields = argc > 2 ? atol(argv[2]) : 2000;
    int avx = has_avx(), avx512 = avx && has_avx512();
    if (procs < 1 || procs > 64 || yields < 1) {
        fprintf(stderr, "usage: xstate_guest [processes 1..64 [yields >= 1]]\n");
        return 2;
    }
    for (int i = 0; i < procs; i++) {
        pid_t pid = fork();
        if (pid < 0) {
            perror("fork");
            return 1;
        }
        if (pid == 0)
            _exit(one((unsigned)i, avx512, avx, yields));
    }
    int bad = 0, st;
    for (int i = 0; i < procs; i++)
        if (wait(&st) < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0)
            bad++;
    const char *what = avx512 ? "zmm0-31, k1-k7" : avx ? "ymm0-15" : "xmm0-15";
    if (bad)
        printf("FAIL: xstate/vector_registers_kept: %d of %d processes found their %s changed "
               "after %ld yields\n", bad, procs, what, yields);
    else
        printf("PASS: xstate/vector_registers_kept (%d processes, %s, %ld yields each)\n",
               procs, what, yields);
    return bad != 0;
}

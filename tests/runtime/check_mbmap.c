/* The Modbus map at every boundary, exceptions, atomic writes, symbol map.
** Expected register values are worked out by hand from docs/modbus.md. */
#include <check.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "config.h"
#include "mbmap.h"
#include "../common/check_run.h"

static int32_t v_dint;          /* CONFIG0.RES0.INST0.D, holding 9000 rw */
static int16_t v_int = 77;      /* CONFIG0.RES0.INST0.I, holding 9002 read-only */
static uint8_t v_bool;          /* CONFIG0.RES0.INST0.B, coil 9000 rw */
static double v_lreal;          /* CONFIG0.RES0.INST0.L, holding 9010 rw */
static float v_real = 1.5f;     /* CONFIG0.RES0.INST0.R, input 3000 */

static const plc_var vars[] = {
    { "CONFIG0.RES0.INST0.D", "DINT", 0, 0, 4, &v_dint },
    { "CONFIG0.RES0.INST0.I", "INT", 0, 0, 2, &v_int },
    { "CONFIG0.RES0.INST0.B", "BOOL", 0, 0, 1, &v_bool },
    { "CONFIG0.RES0.INST0.L", "LREAL", 0, 0, 8, &v_lreal },
    { "CONFIG0.RES0.INST0.R", "REAL", 0, 0, 4, &v_real },
    { "CONFIG0.RES0.INST0.T", "TIME", 0, 0, 16, &v_lreal },
};
static const plc_program prog = { "CONFIG0", NULL, NULL, NULL, NULL, vars, 6 };

static const char *symbol_map =
    "[modbus.symbols]\n"
    "CONFIG0.RES0.INST0.D = holding 9000 rw\n"
    "CONFIG0.RES0.INST0.I = holding 9002\n"
    "CONFIG0.RES0.INST0.B = coil 9000 rw\n"
    "CONFIG0.RES0.INST0.L = holding 9010 rw\n"
    "CONFIG0.RES0.INST0.R = input 3000\n";

static plc_config cfg;
static plc_image img;
static mb_shared *m;
static uint8_t rsp[MB_PDU_MAX];
static size_t rn;

static void setup(void)
{
    char err[600];
    memset(&img, 0, sizeof img);
    v_dint = 0; v_int = 77; v_bool = 0; v_lreal = 0; v_real = 1.5f;
    ck_assert_int_eq(config_defaults(&cfg, err, sizeof err), 0);
    ck_assert_msg(!config_load_string(&cfg, "t.ini", symbol_map, err, sizeof err), "%s", err);
    m = mb_new(&cfg, &prog, err, sizeof err);
    ck_assert_msg(m != NULL, "%s", err);
    mb_publish(m, &img, NULL);
}

static void teardown(void) { mb_free(m); config_free(&cfg); }

/* Send a PDU given as bytes. */
static void pdu(int n, ...)
{
    uint8_t q[300];
    va_list ap;
    va_start(ap, n);
    for (int i = 0; i < n; i++) q[i] = (uint8_t)va_arg(ap, int);
    va_end(ap);
    rn = mb_process(m, q, (size_t)n, rsp);
}

static void req(int fc, unsigned a, unsigned cnt)
{
    pdu(5, fc, a >> 8, a & 255, cnt >> 8, cnt & 255);
}

/* FC 16 / FC 15 with values */
static void write_regs(unsigned a, unsigned n, const uint16_t *v)
{
    uint8_t q[300] = { 16, (uint8_t)(a >> 8), (uint8_t)a, (uint8_t)(n >> 8), (uint8_t)n, (uint8_t)(2 * n) };
    for (unsigned i = 0; i < n; i++) { q[6 + 2 * i] = (uint8_t)(v[i] >> 8); q[7 + 2 * i] = (uint8_t)v[i]; }
    rn = mb_process(m, q, 6 + 2 * n, rsp);
}

static void write_coils(unsigned a, unsigned n, const uint8_t *bits)
{
    uint8_t q[300] = { 15, (uint8_t)(a >> 8), (uint8_t)a, (uint8_t)(n >> 8), (uint8_t)n, (uint8_t)((n + 7) / 8) };
    memset(q + 6, 0, (n + 7) / 8);
    for (unsigned i = 0; i < n; i++) if (bits[i]) q[6 + i / 8] |= (uint8_t)(1 << (i % 8));
    rn = mb_process(m, q, 6 + (n + 7) / 8, rsp);
}

#define EXC(fc, code) do { ck_assert_uint_eq(rn, 2); ck_assert_uint_eq(rsp[0], (fc) | 0x80); ck_assert_uint_eq(rsp[1], code); } while (0)
#define OK(fc) do { ck_assert_msg(rsp[0] == (fc), "exception %u", rsp[1]); } while (0)
static unsigned reg(int i) { return (unsigned)rsp[2 + 2 * i] << 8 | rsp[3 + 2 * i]; }
/* The server's turn (take the newest snapshot, hand writes over), then a
** cycle's start and end. */
static void cycle(void) { mb_flush(m); mb_apply(m, &img); mb_publish(m, &img, NULL); }

START_TEST(coils_edges)
{
    img.qx[0] = 1; img.qx[8191] = 1; img.qx[8190] = 0;
    mb_publish(m, &img, NULL);
    req(1, 0, 1); OK(1); ck_assert_uint_eq(rsp[1], 1); ck_assert_uint_eq(rsp[2], 1);
    req(1, 8190, 2); OK(1); ck_assert_uint_eq(rsp[2], 2);      /* bit 1 = coil 8191 */
    req(1, 8191, 2); EXC(1, 2);                                 /* one past */
    req(1, 8192, 1); EXC(1, 2);
    req(1, 65535, 2); EXC(1, 2);
    req(1, 0, 2000); OK(1); ck_assert_uint_eq(rsp[1], 250);
    req(1, 0, 2001); EXC(1, 3);
    req(1, 0, 0); EXC(1, 3);
    /* %QX1023.7 is coil 8191 */
    pdu(5, 5, 0x1F, 0xFF, 0x00, 0x00); OK(5);                  /* FC5 8191 off */
    cycle();
    ck_assert_uint_eq(img.qx[1023 * 8 + 7], 0);
    pdu(5, 5, 0x00, 0x0B, 0xFF, 0x00); OK(5);                  /* coil 11 = %QX1.3 on */
    ck_assert_uint_eq(rn, 5);
    cycle();
    ck_assert_uint_eq(img.qx[1 * 8 + 3], 1);
    pdu(5, 5, 0x00, 0x0B, 0x12, 0x34); EXC(5, 3);              /* neither on nor off */
    pdu(5, 5, 0x20, 0x00, 0xFF, 0x00); EXC(5, 2);              /* coil 8192 */
}
END_TEST

START_TEST(coils_multi_straddle)
{
    uint8_t bits[3] = { 1, 1, 1 };
    write_coils(8190, 3, bits); EXC(15, 2);                     /* 8190..8192 */
    req(1, 8190, 2); OK(1); ck_assert_uint_eq(rsp[2], 0);      /* nothing landed */
    cycle();
    ck_assert_uint_eq(img.qx[8190], 0); ck_assert_uint_eq(img.qx[8191], 0);
    write_coils(8190, 2, bits); OK(15);
    cycle();
    ck_assert_uint_eq(img.qx[8190], 1); ck_assert_uint_eq(img.qx[8191], 1);
    /* byte count disagreeing with the quantity */
    pdu(7, 15, 0, 0, 0, 9, 1, 0xFF); EXC(15, 3);
}
END_TEST

START_TEST(discrete_edges)
{
    img.ix[8191] = 1; img.ix[7] = 1;
    mb_publish(m, &img, NULL);
    req(2, 0, 8); OK(2); ck_assert_uint_eq(rsp[2], 0x80);
    req(2, 8191, 1); OK(2); ck_assert_uint_eq(rsp[2], 1);
    req(2, 8191, 2); EXC(2, 2);
    req(2, 8192, 1); EXC(2, 2);
}
END_TEST

START_TEST(input_edges)
{
    img_set16(img.iw, 0, 0x0102); img_set16(img.iw, 1023, -2);
    uint16_t diag[MB_DIAG_ALL] = {0};
    diag[0] = 0xABCD; diag[MB_DIAG_N - 1] = 0x4242;
    mb_publish(m, &img, diag);
    req(4, 0, 1); OK(4); ck_assert_uint_eq(reg(0), 0x0102);
    req(4, 1023, 2); OK(4); ck_assert_uint_eq(reg(0), 0xFFFE); ck_assert_uint_eq(reg(1), 0xABCD);
    req(4, 1024 + MB_DIAG_N - 1, 1); OK(4); ck_assert_uint_eq(reg(0), 0x4242);
    req(4, 1024 + MB_DIAG_N - 1, 2); EXC(4, 2);
    req(4, 1024 + MB_DIAG_N, 1); EXC(4, 2);
    req(4, 0, 126); EXC(4, 3);
    req(4, 0, 125); OK(4); ck_assert_uint_eq(rsp[1], 250);
    /* REAL 1.5 = 0x3FC00000, high word first */
    req(4, 3000, 2); OK(4); ck_assert_uint_eq(reg(0), 0x3FC0); ck_assert_uint_eq(reg(1), 0);
    req(4, 3002, 1); EXC(4, 2);
    pdu(6, 6, 0, 0, 0, 1, 0); EXC(6, 3);                       /* FC6 length wrong */
}
END_TEST

START_TEST(holding_edges)
{
    img_set16(img.qw, 0, 1); img_set16(img.qw, 1023, 2);
    img_set16(img.mw, 0, 3); img_set16(img.mw, 1023, 4);
    img_set32(img.md, 0, 0x11223344); img_set32(img.md, 1023, (int32_t)0xA1B2C3D4);
    img_set64(img.ml, 0, 0x0102030405060708LL); img_set64(img.ml, 1023, (int64_t)0xF1F2F3F4F5F6F7F8ULL);
    mb_publish(m, &img, NULL);
    req(3, 0, 1); ck_assert_uint_eq(reg(0), 1);
    req(3, 1023, 2); ck_assert_uint_eq(reg(0), 2); ck_assert_uint_eq(reg(1), 3);  /* %QW1023, %MW0 */
    req(3, 2047, 3); ck_assert_uint_eq(reg(0), 4);
    ck_assert_uint_eq(reg(1), 0x1122); ck_assert_uint_eq(reg(2), 0x3344);       /* %MD0 high first */
    req(3, 4094, 6);
    ck_assert_uint_eq(reg(0), 0xA1B2); ck_assert_uint_eq(reg(1), 0xC3D4);
    ck_assert_uint_eq(reg(2), 0x0102); ck_assert_uint_eq(reg(3), 0x0304);       /* %ML0 MSW first */
    ck_assert_uint_eq(reg(4), 0x0506); ck_assert_uint_eq(reg(5), 0x0708);
    req(3, 8188, 4); OK(3);
    ck_assert_uint_eq(reg(0), 0xF1F2); ck_assert_uint_eq(reg(3), 0xF7F8);
    req(3, 8191, 1); OK(3); ck_assert_uint_eq(reg(0), 0xF7F8);
    req(3, 8191, 2); EXC(3, 2);
    req(3, 8192, 1); EXC(3, 2);
    req(3, 65535, 1); EXC(3, 2);
    req(3, 0, 0); EXC(3, 3);
}
END_TEST

START_TEST(holding_writes)
{
    uint16_t v[4] = { 0x1234, 0x5678, 0x9ABC, 0xDEF0 };
    write_regs(2048 + 10, 2, v); OK(16);                         /* %MD5 */
    ck_assert_uint_eq(rn, 5);
    ck_assert_int_eq(img_get32(img.md, 5), 0);                    /* not before the cycle */
    req(3, 2058, 2); ck_assert_uint_eq(reg(0), 0x1234);           /* but read back at once */
    mb_publish(m, &img, NULL);                                    /* a cycle's publish keeps it */
    req(3, 2058, 2); ck_assert_uint_eq(reg(1), 0x5678);
    cycle();
    ck_assert_int_eq(img_get32(img.md, 5), 0x12345678);
    write_regs(4096 + 4 * 7, 4, v); OK(16);                       /* %ML7 */
    cycle();
    ck_assert(img_get64(img.ml, 7) == (int64_t)0x123456789ABCDEF0ULL);
    /* one register of an %MD keeps the other half */
    pdu(5, 6, 0x08, 0x0B, 0xAA, 0xAA); OK(6);                     /* 2059 = %MD5 low */
    cycle();
    ck_assert_int_eq(img_get32(img.md, 5), 0x1234AAAA);
    /* straddling the end of the map: rejected whole */
    write_regs(8190, 3, v); EXC(16, 2);
    cycle();
    ck_assert(img_get64(img.ml, 1023) == 0);
    /* contiguous tables may be crossed: %QW1023 and %MW0 */
    write_regs(1023, 2, v); OK(16);
    cycle();
    ck_assert_int_eq(img_get16(img.qw, 1023), 0x1234);
    ck_assert_int_eq(img_get16(img.mw, 0), 0x5678);
    /* limits of FC16 */
    uint16_t many[124] = {0};
    write_regs(0, 124, many); EXC(16, 3);
    write_regs(0, 123, many); OK(16);
    pdu(8, 16, 0, 0, 0, 1, 3, 0, 0); EXC(16, 3);                  /* byte count 3 for 1 register */
    pdu(2, 7, 0); EXC(7, 1);                                      /* function not supported */
    pdu(1, 43); EXC(43, 1);
}
END_TEST

START_TEST(fc23)
{
    /* write 2 at 100, read 3 at 99: the write comes first */
    pdu(14, 23, 0, 99, 0, 3, 0, 100, 0, 2, 4, 0x11, 0x11, 0x22, 0x22); OK(23);
    ck_assert_uint_eq(rsp[1], 6);
    ck_assert_uint_eq(reg(0), 0); ck_assert_uint_eq(reg(1), 0x1111); ck_assert_uint_eq(reg(2), 0x2222);
    cycle();
    ck_assert_int_eq(img_get16(img.qw, 101), 0x2222);
    /* read part out of the map: nothing written */
    pdu(12, 23, 0x1F, 0xFF, 0, 2, 0, 5, 0, 1, 2, 0x55, 0x55); EXC(23, 2);
    cycle();
    ck_assert_int_eq(img_get16(img.qw, 5), 0);
}
END_TEST

START_TEST(symbols)
{
    v_dint = -2;
    mb_publish(m, &img, NULL);
    req(3, 9000, 3); OK(3);
    ck_assert_uint_eq(reg(0), 0xFFFF); ck_assert_uint_eq(reg(1), 0xFFFE); ck_assert_uint_eq(reg(2), 77);
    uint16_t v[3] = { 0x0001, 0x0002, 0x0003 };
    write_regs(9000, 3, v); EXC(16, 2);                           /* 9002 is read-only */
    cycle();
    ck_assert_int_eq(v_dint, -2); ck_assert_int_eq(v_int, 77);
    write_regs(9000, 2, v); OK(16);
    ck_assert_int_eq(v_dint, -2);                                 /* lands at the cycle */
    cycle();
    ck_assert_int_eq(v_dint, 0x00010002);
    pdu(5, 6, 0x23, 0x2A, 0, 1); EXC(6, 2);                        /* 9002 */
    req(3, 9003, 1); EXC(3, 2);                                   /* gap after the INT */
    /* LREAL 2.5 = 0x4004000000000000, most significant word first */
    uint16_t d[4] = { 0x4004, 0, 0, 0 };
    write_regs(9010, 4, d); OK(16);
    cycle();
    ck_assert(v_lreal == 2.5);
    /* BOOL symbol as a coil */
    pdu(5, 5, 0x23, 0x28, 0xFF, 0x00); OK(5);
    cycle();
    ck_assert_uint_eq(v_bool, 1);
    req(1, 9000, 2); EXC(1, 2);
    /* the program changes it: clients see the program's value */
    v_dint = 5;
    mb_publish(m, &img, NULL);
    req(3, 9001, 1); ck_assert_uint_eq(reg(0), 5);
}
END_TEST

/* A REAL or LREAL symbol written nan or infinite: exception 03, nothing of
** the request lands (it would run through the program into the outputs). */
START_TEST(symbols_finite)
{
    uint16_t nan[4] = { 0x7FF8, 0, 0, 0 }, inf[4] = { 0xFFF0, 0, 0, 0 }, two[4] = { 0x4000, 0, 0, 0 };

    write_regs(9010, 4, nan); EXC(16, 3);
    write_regs(9010, 4, inf); EXC(16, 3);
    pdu(5, 6, 0x23, 0x32, 0x7F, 0xF0); EXC(6, 3);                /* 9010 alone: +inf whatever follows */
    uint8_t q23[] = { 23, 0x23, 0x28, 0, 2, 0x23, 0x32, 0, 4, 8, 0x7F, 0xF8, 0, 0, 0, 0, 0, 1 };
    rn = mb_process(m, q23, sizeof q23, rsp); EXC(23, 3);

    cycle();
    ck_assert(v_lreal == 0);
    write_regs(9010, 4, two); OK(16);
    cycle();
    ck_assert(v_lreal == 2.0);
    pdu(5, 6, 0x23, 0x33, 0x12, 0x34); OK(6);                   /* a low word: still finite */
    cycle();
    ck_assert(v_lreal == 2.0 * (1.0 + 0x1234 / 1048576.0));     /* 0x40001234 00000000 */
    /* %MD/%ML have no type: any bits go */
    uint16_t md[2] = { 0x7FC0, 0 };
    write_regs(2048, 2, md); OK(16);
}
END_TEST

START_TEST(many_writes_between_cycles)
{
    /* far more writes than cells between two cycles: never busy, last wins */
    uint16_t v[123];
    for (int i = 0; i < 2000; i++) {
        for (int k = 0; k < 123; k++) v[k] = (uint16_t)(i + k);
        write_regs((unsigned)(i % 8) * 1000, 123, v);
        OK(16);
    }
    uint8_t bits[1968];
    for (int i = 0; i < 1968; i++) bits[i] = (uint8_t)(i & 1);
    for (unsigned a = 0; a < 8192 - 1968; a += 1968) { write_coils(a, 1968, bits); OK(15); }
    /* the first write went to the scan at once; all the others, one
    ** element each, in the next batch: two cycles land everything */
    cycle();
    cycle();
    /* the last write at 0 (%QW0..122) was i = 1992: register k = 1992 + k */
    ck_assert_int_eq(img_get16(img.qw, 0), 1992);
    ck_assert_int_eq(img_get16(img.qw, 122), 1992 + 122);
    /* at 5000 (%ML226 from its most significant word) i = 1997 */
    ck_assert(img_get64(img.ml, 226) == (int64_t)((1997ULL << 48) | (1998ULL << 32) | (1999ULL << 16) | 2000ULL));
    ck_assert_uint_eq(img.qx[1], 1);
    ck_assert_uint_eq(img.qx[2], 0);
}
END_TEST

/* A scan on its own thread, cycling as fast as it can: the program's view
** of %MD100 must always be one whole value a client wrote. */
#define VAL_A 0x11112222u
#define VAL_B 0x33334444u
static _Atomic int scan_stop;
static int torn_in_program;

static void *scan_loop(void *arg)
{
    (void)arg;
    while (!atomic_load(&scan_stop)) {
        mb_apply(m, &img);
        uint32_t v = (uint32_t)img_get32(img.md, 100);
        if (v && v != VAL_A && v != VAL_B) torn_in_program++;
        mb_publish(m, &img, NULL);
    }
    return NULL;
}

START_TEST(threads_never_tear)
{
    pthread_t th;
    atomic_store(&scan_stop, 0);
    torn_in_program = 0;
    ck_assert_int_eq(pthread_create(&th, NULL, scan_loop, NULL), 0);
    for (int i = 0; i < 20000; i++) {
        uint32_t v = i % 2 ? VAL_B : VAL_A;
        uint16_t w[2] = { (uint16_t)(v >> 16), (uint16_t)v };
        write_regs(2048 + 200, 2, w); OK(16);                  /* %MD100 */
        req(3, 2048 + 200, 2); OK(3);
        ck_assert_uint_eq((uint32_t)reg(0) << 16 | reg(1), v); /* its own write, whole */
    }
    /* the last batch lands: counted tries, up to a minute, for a loaded host */
    int pending = 1;
    for (int k = 0; k < 600000 && (pending = mb_flush(m)); k++) usleep(100);
    ck_assert_msg(!pending, "the scan thread did not take the last writes");
    atomic_store(&scan_stop, 1);
    pthread_join(th, NULL);
    ck_assert_int_eq(torn_in_program, 0);
    ck_assert_uint_eq((uint32_t)img_get32(img.md, 100), VAL_B);   /* i = 19999 wrote B */
}
END_TEST

static void bad_symbol(const char *text, const char *want)
{
    char err[600];
    plc_config c;
    ck_assert_int_eq(config_defaults(&c, err, sizeof err), 0);
    ck_assert_msg(!config_load_string(&c, "s.ini", text, err, sizeof err), "%s", err);
    mb_shared *x = mb_new(&c, &prog, err, sizeof err);
    ck_assert_msg(x == NULL, "accepted: %s", text);
    ck_assert_msg(strstr(err, want) != NULL, "message '%s' lacks '%s'", err, want);
    config_free(&c);
}

START_TEST(symbol_errors)
{
    bad_symbol("[modbus.symbols]\nCONFIG0.RES0.INST0.NOPE = holding 9000\n", "s.ini:2: [modbus.symbols] CONFIG0.RES0.INST0.NOPE: no such variable");
    bad_symbol("\n[modbus.symbols]\nCONFIG0.RES0.INST0.D = holding 8191\n", "s.ini:3:");
    bad_symbol("[modbus.symbols]\nCONFIG0.RES0.INST0.D = holding 8191\n", "inside the fixed map");
    bad_symbol("[modbus.symbols]\nCONFIG0.RES0.INST0.D = input 1100\n", "inside the fixed map");
    bad_symbol("[modbus.symbols]\nCONFIG0.RES0.INST0.D = holding 9000\nCONFIG0.RES0.INST0.I = holding 9001\n", "overlaps CONFIG0.RES0.INST0.D");
    bad_symbol("[modbus.symbols]\nCONFIG0.RES0.INST0.D = coil 9000\n", "holds a BOOL");
    bad_symbol("[modbus.symbols]\nCONFIG0.RES0.INST0.T = holding 9000\n", "type TIME cannot be mapped");
    bad_symbol("[modbus.symbols]\nCONFIG0.RES0.INST0.L = holding 65533\n", "65536");
}
END_TEST

int main(void)
{
    Suite *s = suite_create("mbmap");
    TCase *t = tcase_create("map");
    tcase_add_checked_fixture(t, setup, teardown);
    tcase_add_test(t, coils_edges);
    tcase_add_test(t, coils_multi_straddle);
    tcase_add_test(t, discrete_edges);
    tcase_add_test(t, input_edges);
    tcase_add_test(t, holding_edges);
    tcase_add_test(t, holding_writes);
    tcase_add_test(t, fc23);
    tcase_add_test(t, symbols);
    tcase_add_test(t, symbols_finite);
    tcase_add_test(t, many_writes_between_cycles);
    tcase_add_test(t, threads_never_tear);
    tcase_add_test(t, symbol_errors);
    suite_add_tcase(s, t);
    return check_run(s);
}

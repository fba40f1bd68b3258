/*
** check_tracemb: the trace block's requests (tracemb.h) served without a
** network, the scan's side driven cycle by cycle: a capture set up, armed
** and read back through the window; and random requests into the block
** (under ASan/UBSan), each answered with a well-formed reply or exception
** and never anything the scan could trip on.
*/
#include <check.h>
#include <stdlib.h>
#include <string.h>
#include "tracemb.h"

static int32_t pos;
static int16_t speed;
static uint8_t go;
static float gain;
static plc_var vars[] = {
    { "CONFIG0.RES0.INST0.POS", "DINT", 0, 0, 4, &pos },
    { "CONFIG0.RES0.INST0.SPEED", "INT", 0, 0, 2, &speed },
    { "CONFIG0.RES0.INST0.GO", "BOOL", 0, 0, 1, &go },
    { "CONFIG0.RES0.INST0.GAIN", "REAL", 0, 0, 4, &gain },
};
static const plc_program prog = { "CONFIG0", NULL, NULL, NULL, NULL, vars, 4 };

static trace *t;
static forcing *f;
static tracemb *tb;

static void setup(void)
{
    t = trace_new(TRACE_MIN_SAMPLES * 64);
    f = force_new(&prog, 1);
    tb = tb_new(t, f, &prog, 1000000);
    ck_assert_ptr_nonnull(tb);
}

static void teardown(void)
{
    tb_free(tb);
    force_free(f);
    trace_free(t);
}

/* FC 16 at a: 0, or the exception code */
static int write16(unsigned a, const uint16_t *r, unsigned n)
{
    uint8_t q[260], rsp[MB_PDU_MAX];
    q[0] = 16; q[1] = (uint8_t)(a >> 8); q[2] = (uint8_t)a; q[3] = 0; q[4] = (uint8_t)n; q[5] = (uint8_t)(2 * n);
    for (unsigned i = 0; i < n; i++) { q[6 + 2 * i] = (uint8_t)(r[i] >> 8); q[7 + 2 * i] = (uint8_t)r[i]; }
    int e;
    ck_assert(tb_touches(q, 6 + 2 * n));
    size_t k = tb_serve(tb, q, 6 + 2 * n, rsp, &e);
    if (!e) return 0;
    ck_assert_uint_eq(k, 2);
    return rsp[1];
}

/* FC 3 at a into out: 0, or the exception code */
static int read3(unsigned a, unsigned n, uint16_t *out)
{
    uint8_t q[5] = { 3, (uint8_t)(a >> 8), (uint8_t)a, 0, (uint8_t)n }, rsp[MB_PDU_MAX];
    int e;
    size_t k = tb_serve(tb, q, 5, rsp, &e);
    if (e) return rsp[1];
    ck_assert_uint_eq(k, 2 + 2 * n);
    for (unsigned i = 0; i < n; i++) out[i] = (uint16_t)(rsp[2 + 2 * i] << 8 | rsp[3 + 2 * i]);
    return 0;
}

START_TEST(capture_through_the_block)
{
    uint16_t claim[] = { 7, 1 }, chans[] = { 7, 3, 0, 0, 0, 1 };
    /* 20 samples, 5 before a rise of GO, every 3rd cycle */
    uint16_t set[] = { 7, 4, 3, 0, 20, 0, 5, 1, 0, 2, 0, 0, 0, 0, 0 }, arm[] = { 7, 5 };
    ck_assert_int_eq(write16(TB_CMD, claim, 2), 0);
    ck_assert_int_eq(write16(TB_CMD, chans, 6), 0);
    ck_assert_int_eq(write16(TB_CMD, set, 15), 0);
    ck_assert_int_eq(write16(TB_CMD, arm, 2), 0);
    uint16_t other[] = { 8, 4, 1, 0, 10, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 };
    ck_assert_int_eq(write16(TB_CMD, other, 15), 6);         /* not the owner */
    for (uint32_t c = 0; c < 300; c++) {
        pos = (int32_t)c * 1000;
        speed = (int16_t)-c;
        go = c >= 100;
        trace_cycle(t, c, c);
    }
    uint16_t st[32], sel[] = { 0, 0, 0 }, w[125];
    ck_assert_int_eq(read3(TB_BASE, 32, st), 0);
    ck_assert_uint_eq(st[3], 1);                             /* readable */
    ck_assert_uint_eq(st[13], 20);
    ck_assert_uint_eq(st[15], 5);
    /* samples every 3rd cycle from 0: the rise (cycle 100) is first seen
    ** at cycle 102, which is sample 5; sample 0 is cycle 87 */
    sel[0] = 0x100;
    ck_assert_int_eq(write16(TB_SEL, sel, 3), 0);
    ck_assert_int_eq(read3(TB_WIN, 40, w), 0);
    for (int i = 0; i < 20; i++) ck_assert_uint_eq((uint32_t)w[2 * i] << 16 | w[2 * i + 1], 87 + 3 * i);
    sel[0] = 0;
    ck_assert_int_eq(write16(TB_SEL, sel, 3), 0);
    ck_assert_int_eq(read3(TB_WIN, 40, w), 0);
    ck_assert_int_eq((int32_t)((uint32_t)w[10] << 16 | w[11]), 102000);
    sel[0] = 1;
    ck_assert_int_eq(write16(TB_SEL, sel, 3), 0);
    ck_assert_int_eq(read3(TB_WIN, 20, w), 0);
    ck_assert_int_eq((int16_t)w[5], -102);
    sel[0] = 2;                                              /* a third channel: none */
    ck_assert_int_eq(write16(TB_SEL, sel, 3), 0);
    ck_assert_int_eq(read3(TB_WIN, 1, w), 2);
}
END_TEST

/* FORCE of var with the 64-bit raw value: 0, or the exception code */
static int force(uint32_t var, uint64_t raw)
{
    uint16_t r[8] = { 0, 17, (uint16_t)(var >> 16), (uint16_t)var,
                      (uint16_t)(raw >> 48), (uint16_t)(raw >> 32), (uint16_t)(raw >> 16), (uint16_t)raw };
    return write16(TB_CMD, r, 8);
}

/* Values no program can be given: a BOOL of 2 (TRUE, and NOT of it TRUE
** too) and a REAL nan or infinity (through the program into a DAC): 03,
** and nothing forced; the ordinary values still are. */
START_TEST(force_values)
{
    uint32_t nan32 = 0x7FC00000u, inf32 = 0x7F800000u, minf32 = 0xFF800000u, one32 = 0x3F800000u;
    ck_assert_int_eq(force(2, 2), 3);
    ck_assert_int_eq(force(2, 0xFF), 3);
    ck_assert_int_eq(force(3, nan32), 3);
    ck_assert_int_eq(force(3, inf32), 3);
    ck_assert_int_eq(force(3, minf32), 3);
    ck_assert_int_eq(force_count(f), 0);
    ck_assert_int_eq(force(2, 1), 0);
    ck_assert_int_eq(force(3, one32), 0);
    ck_assert_int_eq(force(1, 0xFFFF), 0);          /* INT -1 */
    ck_assert_int_eq(force_count(f), 3);
}
END_TEST

START_TEST(random_requests)
{
    srand(12345);
    uint8_t q[300], rsp[MB_PDU_MAX];
    static const uint8_t fcs[] = { 3, 6, 16, 23 };
    static const unsigned bases[] = { TB_BASE, TB_CMD, TB_SEL, TB_WIN, TB_END - 3 };
    int replies = 0, exceptions = 0;
    for (int k = 0; k < 200000; k++) {
        size_t n = 1 + (size_t)(rand() % 260);
        for (size_t i = 0; i < n; i++) q[i] = (uint8_t)rand();
        q[0] = fcs[rand() % 4];
        if (n >= 3 && rand() % 4) {                          /* mostly inside the block */
            unsigned a = bases[rand() % 5] + (unsigned)(rand() % 8);
            q[1] = (uint8_t)(a >> 8); q[2] = (uint8_t)a;
        }
        if (n >= 5 && rand() % 2) { q[3] = 0; q[4] = (uint8_t)(1 + rand() % 20); }
        if (q[0] == 16 && n >= 6 && rand() % 2) { q[5] = (uint8_t)(2 * q[4]); n = 6u + q[5]; }
        if ((q[0] == 3 || q[0] == 6) && n >= 5 && rand() % 2) n = 5;
        if (q[0] == 16 && n >= 6 && rand() % 3 == 0) { q[6] = 0; q[7] = 7; q[8] = 0; q[9] = (uint8_t)(rand() % 20); }
        if (!tb_touches(q, n)) continue;
        int e;
        size_t r = tb_serve(tb, q, n, rsp, &e);
        ck_assert(r >= 2 && r <= MB_PDU_MAX);
        if (e) { ck_assert_uint_eq(rsp[0], q[0] | 0x80); exceptions++; }
        else { ck_assert_uint_eq(rsp[0], q[0]); replies++; }
        if (k % 7 == 0) {
            pos = k;
            go = (k / 70) & 1;
            trace_cycle(t, (uint32_t)k, (uint32_t)k);
            force_begin(f);
            force_apply(f, FORCE_AFTER_INPUTS);
            force_apply(f, FORCE_AFTER_PROGRAM);
            tb_flush(tb);
        }
    }
    ck_assert_int_gt(replies, 1000);
    ck_assert_int_gt(exceptions, 100);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("tracemb");
    TCase *tc = tcase_create("tracemb");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, capture_through_the_block);
    tcase_add_test(tc, random_requests);
    tcase_add_test(tc, force_values);
    suite_add_tcase(s, tc);
    SRunner *r = srunner_create(s);
    srunner_run_all(r, CK_ENV);
    int n = srunner_ntests_failed(r);
    srunner_free(r);
    return n ? 1 : 0;
}

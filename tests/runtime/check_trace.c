/*
** check_trace: the trace engine (trace.h) and forcing (force.h) driven cycle
** by cycle without threads, so that each expectation is the closed form of
** a made-up "program": x = cycle number, b = (cycle MOD 10 >= 5).
*/
#include <check.h>
#include <stdlib.h>
#include <string.h>
#include "force.h"
#include "plc_image.h"
#include "trace.h"

static int32_t x;
static uint8_t b;
static int16_t in_copy, internal;

static trace_chan chan(void *addr, int size, int type) { return (trace_chan){ addr, 0, (uint8_t)size, (uint8_t)type }; }

/* one cycle of the made-up program, then the trace as the scan calls it */
static void cycle(trace *t, uint32_t c)
{
    x = (int32_t)c;
    b = c % 10 >= 5;
    trace_cycle(t, c, c);
}

static trace_setup setup(int trig, uint32_t samples, uint32_t pre, uint32_t decim)
{
    trace_setup s;
    memset(&s, 0, sizeof s);
    s.ch[0] = chan(&x, 4, TT_DINT);
    s.ch[1] = chan(&b, 1, TT_BOOL);
    s.nchan = 2;
    s.samples = samples;
    s.pre = pre;
    s.decim = decim;
    s.trig = trig;
    s.tv = trig == TRIG_UP || trig == TRIG_DOWN ? chan(&x, 4, TT_DINT) : chan(&b, 1, TT_BOOL);
    return s;
}

/* run cycles from c until a capture is readable; the cycle after it */
static uint32_t run_until_done(trace *t, uint32_t c, trace_buf **out)
{
    for (uint32_t k = 0; k < 100000; k++, c++) {
        cycle(t, c);
        if ((*out = trace_take(t))) return c + 1;
    }
    ck_abort_msg("no capture");
    return c;
}

START_TEST(rise_with_pre)
{
    trace *t = trace_new(TRACE_MIN_SAMPLES * 64);
    ck_assert_ptr_nonnull(t);
    trace_setup s = setup(TRIG_RISE, 40, 12, 1);
    trace_arm(t, &s);
    trace_buf *h;
    run_until_done(t, 3, &h);
    /* armed at cycle 3: 12 samples are in by cycle 14; the first rise after
    ** (b from 0 to 1) is at cycle 15 (15 MOD 10 = 5) */
    ck_assert_uint_eq(h->cycle[trace_index(h, 12)], 15);
    ck_assert_uint_eq(trace_value(h, 1, 12), 1);
    ck_assert_uint_eq(trace_value(h, 1, 11), 0);
    for (uint32_t i = 0; i < 40; i++) ck_assert_uint_eq(trace_value(h, 0, i), 3 + i);
    trace_free(t);
}
END_TEST

START_TEST(pre_needs_its_samples)
{
    /* pre 12: the rise at cycle 5 comes with 5 samples only; the next one
    ** (cycle 15) is taken */
    trace *t = trace_new(TRACE_MIN_SAMPLES);
    trace_setup s = setup(TRIG_RISE, 16, 12, 1);
    trace_arm(t, &s);
    trace_buf *h;
    run_until_done(t, 0, &h);
    ck_assert_uint_eq(h->cycle[trace_index(h, 12)], 15);
    ck_assert_uint_eq(h->cycle[trace_index(h, 0)], 3);
    trace_free(t);
}
END_TEST

START_TEST(levels_and_fall)
{
    trace *t = trace_new(TRACE_MIN_SAMPLES * 8);
    trace_setup s = setup(TRIG_UP, 20, 2, 1);
    s.level = 33.5;
    trace_arm(t, &s);
    trace_buf *h;
    uint32_t c = run_until_done(t, 0, &h);
    ck_assert_uint_eq(trace_value(h, 0, 2), 34);
    trace_next(t);
    s = setup(TRIG_DOWN, 20, 0, 1);
    s.level = 1000;                    /* x only rises: never */
    trace_arm(t, &s);
    for (int k = 0; k < 500; k++) cycle(t, c++);
    ck_assert_ptr_null(trace_take(t));
    ck_assert_int_eq(trace_running(t), 1);
    trace_stop(t);
    cycle(t, c++);
    ck_assert_int_eq(trace_running(t), 0);
    s = setup(TRIG_FALL, 20, 3, 1);
    trace_arm(t, &s);
    run_until_done(t, c, &h);
    ck_assert_uint_eq(h->cycle[trace_index(h, 3)] % 10, 0);
    ck_assert_uint_eq(trace_value(h, 1, 2), 1);
    trace_free(t);
}
END_TEST

START_TEST(decimation_and_manual)
{
    trace *t = trace_new(TRACE_MIN_SAMPLES * 8);
    trace_setup s = setup(TRIG_MANUAL, 30, 5, 4);
    trace_arm(t, &s);
    trace_trigger(t);                  /* waits for its 5 pre-trigger samples */
    trace_buf *h;
    run_until_done(t, 100, &h);
    for (uint32_t i = 0; i < 30; i++) ck_assert_uint_eq(h->cycle[trace_index(h, i)], 100 + 4 * i);
    trace_free(t);
}
END_TEST

START_TEST(repeat_waits_for_a_buffer)
{
    trace *t = trace_new(TRACE_MIN_SAMPLES);
    trace_setup s = setup(TRIG_RISE, 10, 0, 1);
    s.repeat = 1;
    trace_arm(t, &s);
    uint32_t c = 0;
    for (; c < 100; c++) cycle(t, c);
    /* captures at the rises of 5 and 25 fill both buffers (re-armed at 15, the
    ** second one needs a sample before its rise); the scan waits */
    trace_buf *h = trace_take(t);
    ck_assert_uint_eq(h->seq, 1);
    ck_assert_uint_eq(h->cycle[trace_index(h, 0)], 5);
    ck_assert_int_eq(atomic_load(&t->state_pub), TRACE_WAIT_BUFFER);
    trace_next(t);
    h = trace_take(t);
    ck_assert_uint_eq(h->seq, 2);
    ck_assert_uint_eq(h->cycle[trace_index(h, 0)], 25);
    for (; c < 120; c++) cycle(t, c);  /* a buffer free again: the rise at 105 */
    trace_next(t);
    h = trace_take(t);
    ck_assert_uint_eq(h->seq, 3);
    ck_assert_uint_eq(h->cycle[trace_index(h, 0)], 105);
    trace_free(t);
}
END_TEST

START_TEST(forcing_moments)
{
    static plc_var vars[3];
    vars[0] = (plc_var){ "C.R.I.IN", "INT", 0, 0, 2, plc_img.iw + 6 };
    vars[1] = (plc_var){ "C.R.I.OUT", "INT", 0, 0, 2, plc_img.qw + 2 };
    vars[2] = (plc_var){ "C.R.I.V", "INT", 0, 0, 2, &internal };
    plc_program p = { "C", NULL, NULL, NULL, NULL, vars, 3 };
    ck_assert_int_eq(force_area(&vars[0]), FORCE_INPUT);
    ck_assert_int_eq(force_area(&vars[1]), FORCE_OUTPUT);
    ck_assert_int_eq(force_area(&vars[2]), FORCE_INTERNAL);
    forcing *f = force_new(&p, 1);
    ck_assert_int_eq(force_set(f, 0, 0xFFF9), 0);        /* -7 */
    ck_assert_int_eq(force_set(f, 1, 1234), 0);
    ck_assert_int_eq(force_set(f, 2, 5), 0);
    ck_assert_int_eq(force_set(f, 3, 5), -1);
    ck_assert_int_eq(force_count(f), 3);
    /* the first change was published at once; the others wait until the
    ** scan moved to it (start of a cycle) */
    ck_assert_int_eq(force_flush(f), 1);
    force_begin(f);
    ck_assert_int_eq(force_flush(f), 0);
    force_begin(f);
    img_set16(plc_img.iw, 3, 100);
    img_set16(plc_img.qw, 1, 0);
    internal = 0;
    force_apply(f, FORCE_AFTER_INPUTS);
    in_copy = img_get16(plc_img.iw, 3);
    ck_assert_int_eq(in_copy, -7);
    ck_assert_int_eq(internal, 5);
    ck_assert_int_eq(img_get16(plc_img.qw, 1), 0);      /* outputs: later */
    internal = 9;                                       /* the program writes */
    img_set16(plc_img.qw, 1, 1);
    force_apply(f, FORCE_AFTER_PROGRAM);
    ck_assert_int_eq(internal, 5);
    ck_assert_int_eq(img_get16(plc_img.qw, 1), 1234);
    /* a change waits until the scan moved to the last table published */
    force_clear(f, 2);
    force_clear_all(f);
    ck_assert_int_eq(force_flush(f), 1);
    force_begin(f);
    ck_assert_int_eq(force_flush(f), 0);
    force_begin(f);
    internal = 9;
    force_apply(f, FORCE_AFTER_PROGRAM);
    ck_assert_int_eq(internal, 9);
    ck_assert_int_eq(force_count(f), 0);
    ck_assert_int_eq(force_is_forced(f, 1), 0);
    force_free(f);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("trace");
    TCase *tc = tcase_create("trace");
    tcase_add_test(tc, rise_with_pre);
    tcase_add_test(tc, pre_needs_its_samples);
    tcase_add_test(tc, levels_and_fall);
    tcase_add_test(tc, decimation_and_manual);
    tcase_add_test(tc, repeat_waits_for_a_buffer);
    tcase_add_test(tc, forcing_moments);
    suite_add_tcase(s, tc);
    SRunner *r = srunner_create(s);
    srunner_run_all(r, CK_ENV);
    int n = srunner_ntests_failed(r);
    srunner_free(r);
    return n ? 1 : 0;
}

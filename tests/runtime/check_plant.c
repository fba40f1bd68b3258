/* The plant model against hand-computed responses (first-order lag:
** x(t) = v (t - lag (1 - exp(-t/lag))); zero pulses at zoff + k cpr). */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include "../../c_blocks/plant.h"
#include "../common/check_run.h"

static plant s;

static void run(plant_params *p, int16_t dac, int steps, double dt)
{
    plant_init(&s, p);
    for (int i = 0; i < steps; i++) plant_step(&s, dac, dt);
}

START_TEST(lag_response)
{
    plant_params p;
    plant_defaults(&p);           /* maxvel 100000, lag 0.005 (docs/config.md) */
    ck_assert(p.maxvel == 100000 && p.lag == 0.005);
    run(&p, 16384, 1000, 1e-3);
    double v = 100000 * (16384 * 10.0 / 32767) / 10;            /* 50001.5 counts/s */
    double x = v * (1.0 - 0.005);                                /* 49751.5 */
    ck_assert_msg(fabs(plant_counter(&s) - x) <= 5, "counter %d, expected %.1f", plant_counter(&s), x);
    ck_assert_msg(fabs(s.vl - v) < 1, "speed %.1f", s.vl);
    /* two thirds of the way: 1 - e^-1 of the speed after one lag */
    run(&p, 16384, 5, 1e-3);
    ck_assert_msg(fabs(s.vm - v * (1 - exp(-1))) < 0.01 * v, "speed after one lag %.1f", s.vm);
}
END_TEST

START_TEST(zero_pulses)
{
    plant_params p;
    plant_defaults(&p);
    p.zero_offset = 123;
    run(&p, 16384, 1000, 1e-3);   /* to ~49004: pulses at 123, 4123, ..., 48123 */
    ck_assert_int_eq(s.latch, 48123);
    ck_assert_uint_eq(s.zeros, 13);
    run(&p, -16384, 1000, 1e-3);  /* down to ~-49004: -3877 ... -47877 */
    ck_assert_int_eq(s.latch, -47877);
    ck_assert_uint_eq(s.zeros, 12);
    /* the same with 10 ms steps: the latched count does not depend on the step */
    run(&p, 16384, 100, 1e-2);
    ck_assert_int_eq(s.latch, 48123);
}
END_TEST

START_TEST(dead_band_offset_drift)
{
    plant_params p;
    plant_defaults(&p);
    p.deadband = 0.5;
    run(&p, 1000, 1000, 1e-3);    /* 0.305 V: inside the dead band */
    ck_assert_int_eq(plant_counter(&s), 0);
    plant_defaults(&p);
    p.offset = 0.1;               /* 0.1 V = 1000 counts/s with the DAC at 0 */
    run(&p, 0, 1000, 1e-3);       /* x(1) = 1000 (1 - lag) = 995 */
    ck_assert_msg(abs(plant_counter(&s) - 995) <= 2, "offset: %d", plant_counter(&s));
    plant_defaults(&p);
    p.drift = 0.1;                /* v(t) = 1000 t: x(1) = 500 - 1000 lag (5) */
    run(&p, 0, 1000, 1e-3);
    ck_assert_msg(abs(plant_counter(&s) - 495) <= 3, "drift: %d", plant_counter(&s));
}
END_TEST

START_TEST(resonance)
{
    plant_params p;
    plant_defaults(&p);
    p.lag = 0;                    /* a speed step on the motor */
    p.resonance = 10;
    p.damping = 0.05;
    plant_init(&s, &p);
    double peak = 0;
    for (int i = 0; i < 200; i++) {
        plant_step(&s, 16384, 1e-3);
        if (s.vl > peak) peak = s.vl;
    }
    ck_assert_msg(peak > 1.5 * 50001.5, "load speed peak %.0f: no resonance", peak);
    for (int i = 0; i < 3000; i++) plant_step(&s, 16384, 1e-3);
    ck_assert_msg(fabs(s.vl - 50001.5) < 500, "load speed %.0f does not settle", s.vl);
    p.resonance = 0;              /* rigid: load follows the motor */
    run(&p, 16384, 100, 1e-3);
    ck_assert(s.xl == s.xm);
}
END_TEST

START_TEST(cam)
{
    plant_params p;
    plant_defaults(&p);
    p.cam_low = 1000;
    p.cam_high = 2000;
    p.start = 500;
    plant_init(&s, &p);
    ck_assert_int_eq(plant_cam(&s), 0);
    p.start = 1500;
    plant_init(&s, &p);
    ck_assert_int_eq(plant_cam(&s), 1);
    p.start = 2000.5;
    plant_init(&s, &p);
    ck_assert_int_eq(plant_cam(&s), 0);
}
END_TEST

/* master axis: x = start + speed t (+ amp/(2 pi f) (1 - cos 2 pi f t)) */
START_TEST(master_axis)
{
    plant_master m;
    plant_master_params p = { 4000, 0, 0, 100 };
    plant_master_init(&m, &p);
    for (int i = 0; i < 2500; i++) plant_master_step(&m, 1e-3);
    ck_assert_msg(fabs(m.x - (100 + 4000 * 2.5)) < 1e-6, "master %.6f, expected 10100", m.x);
    ck_assert_int_ge(plant_master_counter(&m), 10099);
    ck_assert_int_le(plant_master_counter(&m), 10100);
    p = (plant_master_params){ 4000, 1000, 2, 0 };
    plant_master_init(&m, &p);
    for (int i = 0; i < 125; i++) plant_master_step(&m, 1e-3);        /* a quarter period of 2 Hz */
    double x = 4000 * 0.125 + 1000 / (2 * M_PI * 2) * (1 - cos(M_PI / 2));
    ck_assert_msg(fabs(m.x - x) < 1e-6, "master %.6f, expected %.6f", m.x, x);
    ck_assert_int_eq(plant_master_counter(&m), (int)floor(x));
}
END_TEST

/* markers: one pulse per pitch, each within +-noise of first + k pitch, the
** latch the count there; none backwards; noise 0 exact */
START_TEST(markers)
{
    plant_marker mk;
    plant_marker_params p = { 1000, 4000, 0, 1 };
    plant_marker_init(&mk, &p);
    double x = 0;
    for (int i = 0; i < 20000; i++) { plant_marker_step(&mk, x, x + 3.0); x += 3.0; }  /* to 60000 */
    ck_assert_uint_eq(mk.count, 15);                 /* 1000, 5000, ..., 57000 */
    ck_assert_int_eq(mk.latch, 57000);
    p.noise = 50;
    plant_marker_init(&mk, &p);
    x = 0;
    int pulses = 0, bad = 0;
    double lo = 1e9, hi = -1e9;
    for (int i = 0; i < 20000; i++) {
        plant_marker_step(&mk, x, x + 3.0);
        x += 3.0;
        if (mk.on) {
            pulses++;
            double k = round((mk.latch - 1000) / 4000.0), e = mk.latch - (1000 + 4000 * k);
            if (fabs(e) > 50 || mk.latch > x || mk.latch < x - 3.0 - 1) bad++;
            if (e < lo) lo = e;
            if (e > hi) hi = e;
        }
    }
    ck_assert_int_eq(pulses, 15);
    ck_assert_int_eq(bad, 0);
    ck_assert_msg(hi - lo > 20, "noise spread %.0f..%.0f: the noise is not applied", lo, hi);
    uint32_t before = mk.count;
    for (int i = 0; i < 5000; i++) { plant_marker_step(&mk, x, x - 3.0); x -= 3.0; }
    ck_assert_uint_eq(mk.count, before);
}
END_TEST

int main(void)
{
    Suite *su = suite_create("plant");
    TCase *t = tcase_create("model");
    tcase_add_test(t, lag_response);
    tcase_add_test(t, zero_pulses);
    tcase_add_test(t, dead_band_offset_drift);
    tcase_add_test(t, resonance);
    tcase_add_test(t, cam);
    tcase_add_test(t, master_axis);
    tcase_add_test(t, markers);
    suite_add_tcase(su, t);
    return check_run(su);
}

/* The plant's elastic modes (c_blocks/plant.h) against closed-form responses
** of the mode d'' + 2 zeta w d' + w^2 d = -a_motor + f:
**   force step F, motor still:  d = F/w^2 (1 - e^(-s t)(cos wd t + s/wd sin wd t)),
**                               d' = F/wd e^(-s t) sin wd t,
**                               d'' = F e^(-s t)(cos wd t - s/wd sin wd t),
**   with s = zeta w, wd = w sqrt(1 - zeta^2);
**   motor speed step v (no lag): d' jumps to -v, then d = -v/wd e^(-s t) sin wd t;
**   sine force A sin(W t), steady state: |d| = A / sqrt((w^2 - W^2)^2 + (2 zeta w W)^2).
** The measured damped frequency and log decrement of a free decay must give
** the parameters back within 1 %. */
#include <check.h>
#include <math.h>
#include <string.h>
#include "../../c_blocks/plant.h"
#include "../common/check_run.h"

static plant s;

static void one_mode(plant_params *p, double hz, double zeta)
{
    plant_defaults(p);
    p->mode_hz[0] = hz;
    p->mode_zeta[0] = zeta;
}

static double step_d(double F, double hz, double zeta, double t)
{
    double w = 2 * M_PI * hz, sg = zeta * w, wd = w * sqrt(1 - zeta * zeta);
    return F / (w * w) * (1 - exp(-sg * t) * (cos(wd * t) + sg / wd * sin(wd * t)));
}

static double step_a(double F, double hz, double zeta, double t)
{
    double w = 2 * M_PI * hz, sg = zeta * w, wd = w * sqrt(1 - zeta * zeta);
    return F * exp(-sg * t) * (cos(wd * t) - sg / wd * sin(wd * t));
}

START_TEST(force_step_closed_form)
{
    plant_params p;
    one_mode(&p, 53, 0.05);
    plant_init(&s, &p);
    s.force = 2e6;               /* counts/s^2 */
    double worst = 0, worsta = 0, amp = 2e6 / pow(2 * M_PI * 53, 2);
    for (int i = 1; i <= 500; i++) {
        plant_step(&s, 0, 1e-3);
        double t = i * 1e-3;
        worst = fmax(worst, fabs(s.xl - step_d(2e6, 53, 0.05, t)));
        worsta = fmax(worsta, fabs(s.al - step_a(2e6, 53, 0.05, t)));
        ck_assert_int_eq(plant_motor_counter(&s), 0);   /* the motor does not move */
    }
    ck_assert_msg(worst < 1e-6 * amp, "position off by %g counts (static deflection %g)", worst, amp);
    ck_assert_msg(worsta < 1e-6 * 2e6, "acceleration off by %g counts/s^2", worsta);
}
END_TEST

/* parabolic interpolation of a peak through three samples */
static void peak3(double y0, double y1, double y2, double *dx, double *y)
{
    double den = y0 - 2 * y1 + y2;
    *dx = den != 0 ? 0.5 * (y0 - y2) / den : 0;
    *y = y1 - 0.25 * (y0 - y2) * *dx;
}

/* free decay sampled at 0.1 ms: damped frequency and zeta from the trace */
static void measure(double hz, double zeta)
{
    plant_params p;
    one_mode(&p, hz, zeta);
    plant_init(&s, &p);
    s.force = 1e6;
    double F = 1e6, dstat = F / pow(2 * M_PI * hz, 2), dt = 1e-4;
    int n = (int)(8 / (zeta * 2 * M_PI * hz) / dt);  /* until ~e^-8 */
    double y[3] = { 0, 0, 0 }, tp[64], ap[64];
    int np = 0;
    for (int i = 1; i <= n && np < 64; i++) {
        plant_step(&s, 0, dt);
        y[0] = y[1]; y[1] = y[2]; y[2] = s.xl - dstat;
        if (i >= 3 && y[1] > y[0] && y[1] >= y[2] && y[1] > 0) {
            double dx, yy;
            peak3(y[0], y[1], y[2], &dx, &yy);
            tp[np] = (i - 1 + dx) * dt;
            ap[np++] = yy;
        }
    }
    ck_assert_msg(np >= 4, "only %d peaks", np);
    int k = np - 1 < 6 ? np - 1 : 6;
    double fd = k / (tp[k] - tp[0]);
    double delta = log(ap[0] / ap[k]) / k;
    double z = delta / sqrt(4 * M_PI * M_PI + delta * delta);
    double fd_exp = hz * sqrt(1 - zeta * zeta);
    ck_assert_msg(fabs(fd / fd_exp - 1) < 0.01, "%g Hz zeta %g: damped frequency %g, expected %g", hz, zeta, fd, fd_exp);
    ck_assert_msg(fabs(z / zeta - 1) < 0.01, "%g Hz zeta %g: log decrement gives zeta %g", hz, zeta, z);
}

START_TEST(free_decay_frequency_and_zeta)
{
    measure(53, 0.05);
    measure(11, 0.1);
    measure(200, 0.02);
    measure(53, 0.3);
}
END_TEST

START_TEST(motor_speed_step_kicks_the_mode)
{
    plant_params p;
    one_mode(&p, 20, 0.1);
    p.lag = 0;
    plant_init(&s, &p);
    double v = 100000 * (16384 * 10.0 / 32767) / 10, w = 2 * M_PI * 20;
    double sg = 0.1 * w, wd = w * sqrt(1 - 0.01), worst = 0;
    for (int i = 1; i <= 300; i++) {
        plant_step(&s, 16384, 1e-3);
        double t = i * 1e-3;
        double vl = v - v * exp(-sg * t) * (cos(wd * t) - sg / wd * sin(wd * t));
        worst = fmax(worst, fabs(s.vl - vl));
        ck_assert(s.vm == v);
        ck_assert_msg(fabs(s.xm - v * t) < 1e-6 * v, "motor position %g at %g s", s.xm, t);
    }
    ck_assert_msg(worst < 1e-6 * v, "load speed off by %g counts/s", worst);
}
END_TEST

START_TEST(lag_unchanged_by_modes)
{
    plant_params p;
    one_mode(&p, 53, 0.05);
    p.lag = 0.02;
    plant_init(&s, &p);
    double v = 100000 * (16384 * 10.0 / 32767) / 10;
    for (int i = 1; i <= 100; i++) {
        plant_step(&s, 16384, 1e-3);
        double t = i * 1e-3;
        ck_assert_msg(fabs(s.vm - v * (1 - exp(-t / 0.02))) < 1e-9 * v, "motor speed %g", s.vm);
        ck_assert_msg(fabs(s.xm - v * (t - 0.02 * (1 - exp(-t / 0.02)))) < 1e-6 * v, "motor position %g", s.xm);
    }
}
END_TEST

START_TEST(two_modes_superpose_by_share)
{
    plant_params p;
    plant_defaults(&p);
    p.mode_hz[0] = 11; p.mode_zeta[0] = 0.08; p.mode_share[0] = 3;
    p.mode_hz[1] = 53; p.mode_zeta[1] = 0.03; p.mode_share[1] = 1;
    plant_init(&s, &p);
    s.force = 1e6;
    double worst = 0, worsta = 0;
    for (int i = 1; i <= 400; i++) {
        plant_step(&s, 0, 1e-3);
        double t = i * 1e-3;
        double x = 0.75 * step_d(1e6, 11, 0.08, t) + 0.25 * step_d(1e6, 53, 0.03, t);
        double a = 0.75 * step_a(1e6, 11, 0.08, t) + 0.25 * step_a(1e6, 53, 0.03, t);
        worst = fmax(worst, fabs(s.xl - x));
        worsta = fmax(worsta, fabs(s.al - a));
    }
    ck_assert_msg(worst < 1e-3, "load position off by %g counts", worst);
    ck_assert_msg(worsta < 1, "load acceleration off by %g counts/s^2", worsta);
}
END_TEST

START_TEST(sine_disturbance_steady_amplitude)
{
    plant_params p;
    one_mode(&p, 53, 0.05);
    p.dist_amp = 1e5;
    p.dist_hz = 50;
    p.dist_start = 0.1;
    plant_init(&s, &p);
    double w = 2 * M_PI * 53, W = 2 * M_PI * 50;
    double dmag = 1e5 / sqrt(pow(w * w - W * W, 2) + pow(2 * 0.05 * w * W, 2));
    double amax = 0;
    for (int i = 1; i <= 30000; i++) {     /* 3 s at 0.1 ms; transient e^-50 gone */
        plant_step(&s, 0, 1e-4);
        if (i * 1e-4 < 0.099) ck_assert(s.xl == 0);   /* nothing before dist_start */
        if (i > 25000) amax = fmax(amax, fabs(s.al));
    }
    /* the load acceleration: W^2 |d| (the motor is still) */
    ck_assert_msg(fabs(amax / (W * W * dmag) - 1) < 0.005, "acceleration amplitude %g, expected %g", amax, W * W * dmag);
}
END_TEST

START_TEST(array_form_matches)
{
    plant_params p;
    one_mode(&p, 53, 0.05);
    p.mode_hz[1] = 90; p.mode_zeta[1] = 0.1; p.mode_share[1] = 0.5;
    plant_init(&s, &p);
    double v[PA_N];
    memset(v, 0, sizeof v);
    v[PA_MAXVEL] = p.maxvel; v[PA_LAG] = p.lag; v[PA_CPR] = p.counts_per_rev; v[PA_DAMP] = p.damping;
    v[PA_CAMLO] = p.cam_low; v[PA_CAMHI] = p.cam_high; v[PA_T] = -1;
    v[PA_M1HZ] = 53; v[PA_M1ZETA] = 0.05; v[PA_M1SHARE] = 1;
    v[PA_M2HZ] = 90; v[PA_M2ZETA] = 0.1; v[PA_M2SHARE] = 0.5;
    for (int i = 0; i < 200; i++) {
        int16_t dac = i < 100 ? 8000 : -3000;
        s.force = v[PA_FORCE] = i < 50 ? 0 : 5e5;
        plant_step(&s, dac, 1e-3);
        plant_step_array(v, dac, 1e-3);
        ck_assert(v[PA_XL] == s.xl && v[PA_VL] == s.vl && v[PA_ACC] == s.al);
        ck_assert(v[PA_MCOUNTER] == plant_motor_counter(&s) && v[PA_COUNTER] == plant_counter(&s));
    }
}
END_TEST

START_TEST(without_modes_the_legacy_model)
{
    plant_params p;
    plant_defaults(&p);
    ck_assert(!plant_has_modes(&p));
    p.mode_hz[1] = 1;
    ck_assert(plant_has_modes(&p));
    /* rigid: motor and load encoders agree; the acceleration is the step's mean */
    plant_defaults(&p);
    plant_init(&s, &p);
    double v0 = 0;
    for (int i = 0; i < 50; i++) {
        v0 = s.vl;
        plant_step(&s, 16384, 1e-3);
        ck_assert_int_eq(plant_motor_counter(&s), plant_counter(&s));
    }
    ck_assert(fabs(s.al - (s.vl - v0) / 1e-3) < 1e-6 * fabs(s.al));
}
END_TEST

int main(void)
{
    Suite *su = suite_create("plant_modes");
    TCase *t = tcase_create("modes");
    tcase_add_test(t, force_step_closed_form);
    tcase_add_test(t, free_decay_frequency_and_zeta);
    tcase_add_test(t, motor_speed_step_kicks_the_mode);
    tcase_add_test(t, lag_unchanged_by_modes);
    tcase_add_test(t, two_modes_superpose_by_share);
    tcase_add_test(t, sine_disturbance_steady_amplitude);
    tcase_add_test(t, array_form_matches);
    tcase_add_test(t, without_modes_the_legacy_model);
    suite_add_tcase(su, t);
    return check_run(su);
}

/* plant.c: see plant.h. */
#include <math.h>
#include "plant.h"

void plant_defaults(plant_params *p)
{
    *p = (plant_params){
        .maxvel = 100000, .lag = 0.005, .counts_per_rev = 4000,
        .resonance = 0, .damping = 0.1, .cam_low = 1, .cam_high = 0,
    };
}

void plant_init(plant *s, const plant_params *p)
{
    *s = (plant){ .p = *p };
    s->xm = s->xl = p->start;
}

/* Next zero-pulse position strictly above x (or at/below, going down). */
static void zero_pulses(plant *s, double x0, double x1)
{
    double cpr = s->p.counts_per_rev, z = s->p.zero_offset;
    if (cpr <= 0 || x0 == x1) return;
    double lo = x0 < x1 ? x0 : x1, hi = x0 < x1 ? x1 : x0;
    /* zero pulses k with lo < z + k*cpr <= hi (crossed this step) */
    double kfirst = floor((lo - z) / cpr) + 1, klast = floor((hi - z) / cpr);
    if (klast < kfirst) return;
    double k = x1 > x0 ? klast : kfirst;   /* the last one crossed */
    s->latch = (int32_t)(int64_t)(z + k * cpr);
    s->zeros += (uint32_t)(klast - kfirst + 1);
    s->zero = 1;
}

static void substep(plant *s, double u, double h)
{
    const plant_params *p = &s->p;
    double volts = u + p->offset + p->drift * s->t;
    double ref = fabs(volts) <= p->deadband ? 0 : p->maxvel * volts / 10.0;
    if (p->lag > 0) s->vm += (ref - s->vm) * (1 - exp(-h / p->lag));
    else s->vm = ref;
    s->xm += s->vm * h;
    if (p->resonance > 0) {
        double w = 2 * M_PI * p->resonance;
        double a = w * w * (s->xm - s->xl) + 2 * p->damping * w * (s->vm - s->vl);
        s->vl += a * h;          /* semi-implicit Euler: stable for h*w < 2 */
        s->xl += s->vl * h;
    } else {
        s->vl = s->vm;
        s->xl = s->xm;
    }
    s->t += h;
}

void plant_step(plant *s, int16_t dac, double dt)
{
    double u = dac * 10.0 / 32767.0, x0 = s->xl;
    s->zero = 0;
    if (dt <= 0) return;
    /* sub-steps short against the resonance and the lag */
    double hmax = 1e-4;
    if (s->p.resonance > 0) { double h = 0.05 / s->p.resonance; if (h < hmax) hmax = h; }
    int n = (int)ceil(dt / hmax);
    if (n > 100000) n = 100000;
    for (int i = 0; i < n; i++) substep(s, u, dt / n);
    zero_pulses(s, x0, s->xl);
}

int32_t plant_counter(const plant *s)
{
    return (int32_t)(uint32_t)(int64_t)floor(s->xl);
}

int plant_cam(const plant *s)
{
    return s->p.cam_low <= s->p.cam_high && s->xl >= s->p.cam_low && s->xl <= s->p.cam_high;
}

void plant_step_array(double *v, int16_t dac, double dt)
{
    plant s;
    plant_params p = {
        v[PA_MAXVEL], v[PA_LAG], v[PA_OFFSET], v[PA_DRIFT], v[PA_DEADBAND],
        v[PA_CPR], v[PA_ZOFF], v[PA_RES], v[PA_DAMP], v[PA_CAMLO], v[PA_CAMHI],
        v[PA_START],
    };
    if (v[PA_T] < 0) plant_init(&s, &p);
    else {
        s = (plant){ .p = p, .t = v[PA_T], .vm = v[PA_VM], .xm = v[PA_XM],
                     .vl = v[PA_VL], .xl = v[PA_XL], .latch = (int32_t)v[PA_LATCH],
                     .zeros = (uint32_t)v[PA_ZEROS] };
    }
    plant_step(&s, dac, dt);
    v[PA_T] = s.t; v[PA_VM] = s.vm; v[PA_XM] = s.xm; v[PA_VL] = s.vl; v[PA_XL] = s.xl;
    v[PA_LATCH] = s.latch; v[PA_ZEROS] = s.zeros;
    v[PA_COUNTER] = plant_counter(&s); v[PA_ZERO] = s.zero; v[PA_CAM] = plant_cam(&s);
}

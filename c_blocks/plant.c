/* plant.c: see plant.h. */
#include <math.h>
#include <string.h>
#include "plant.h"

void plant_defaults(plant_params *p)
{
    *p = (plant_params){
        .maxvel = 100000, .lag = 0.005, .counts_per_rev = 4000,
        .resonance = 0, .damping = 0.1, .cam_low = 1, .cam_high = 0,
        .mode_share = { 1, 1 },
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

int plant_has_modes(const plant_params *p)
{
    return p->mode_hz[0] > 0 || p->mode_hz[1] > 0;
}

/* ---- elastic modes: exact discretisation ----
** State z = [vm, xm, d1, d1', d2, d2'], inputs u = [ref, f] held over a
** sub-step h: z(t+h) = Phi z + Gamma u with [Phi Gamma] the top rows of
** expm([[A B] [0 0]] h), computed once per h and parameter set. */
enum { Z_VM, Z_XM, Z_D1, Z_D1V, Z_D2, Z_D2V, Z_N, U_REF = Z_N, U_F, ZU_N };

static void mat_mul(double r[ZU_N][ZU_N], double a[ZU_N][ZU_N], double b[ZU_N][ZU_N])
{
    double t[ZU_N][ZU_N];
    for (int i = 0; i < ZU_N; i++)
        for (int j = 0; j < ZU_N; j++) {
            double acc = 0;
            for (int k = 0; k < ZU_N; k++) acc += a[i][k] * b[k][j];
            t[i][j] = acc;
        }
    memcpy(r, t, sizeof t);
}

/* expm by scaling and squaring with a Taylor series to 1e-17 relative. */
static void mat_exp(double e[ZU_N][ZU_N], double m[ZU_N][ZU_N])
{
    double norm = 0;
    for (int i = 0; i < ZU_N; i++) {
        double r = 0;
        for (int j = 0; j < ZU_N; j++) r += fabs(m[i][j]);
        if (r > norm) norm = r;
    }
    int sq = 0;
    while (norm > 0.25 && sq < 60) { norm /= 2; sq++; }
    double a[ZU_N][ZU_N], term[ZU_N][ZU_N];
    for (int i = 0; i < ZU_N; i++)
        for (int j = 0; j < ZU_N; j++) {
            a[i][j] = ldexp(m[i][j], -sq);
            e[i][j] = term[i][j] = (i == j);
        }
    for (int k = 1; k <= 18; k++) {
        mat_mul(term, term, a);
        for (int i = 0; i < ZU_N; i++)
            for (int j = 0; j < ZU_N; j++) { term[i][j] /= k; e[i][j] += term[i][j]; }
    }
    while (sq-- > 0) mat_mul(e, e, e);
}

static double mode_weight(const plant_params *p, int i)
{
    double sum = 0;
    for (int k = 0; k < 2; k++) if (p->mode_hz[k] > 0) sum += p->mode_share[k];
    return p->mode_hz[i] > 0 && sum > 0 ? p->mode_share[i] / sum : 0;
}

static void modes_discretise(plant *s, double h)
{
    const plant_params *p = &s->p;
    double m[ZU_N][ZU_N] = { { 0 } }, e[ZU_N][ZU_N];
    double inv = p->lag > 0 ? 1 / p->lag : 0;   /* lag 0: vm jumps, handled outside */
    m[Z_VM][Z_VM] = -inv; m[Z_VM][U_REF] = inv;
    m[Z_XM][Z_VM] = 1;
    for (int i = 0; i < 2; i++) {
        if (p->mode_hz[i] <= 0) continue;
        int d = Z_D1 + 2 * i, dv = d + 1;
        double w = 2 * M_PI * p->mode_hz[i];
        m[d][dv] = 1;
        m[dv][d] = -w * w;
        m[dv][dv] = -2 * p->mode_zeta[i] * w;
        /* - motor acceleration + f */
        m[dv][Z_VM] = inv; m[dv][U_REF] = -inv;
        m[dv][U_F] = 1;
    }
    for (int i = 0; i < ZU_N; i++) for (int j = 0; j < ZU_N; j++) m[i][j] *= h;
    mat_exp(e, m);
    for (int i = 0; i < Z_N; i++) for (int j = 0; j < ZU_N; j++) s->c_phi[i][j] = e[i][j];
    s->c_h = h;
}

static double disturbance(const plant_params *p, double t)
{
    if (p->dist_amp == 0 || t < p->dist_start) return 0;
    return p->dist_hz > 0 ? p->dist_amp * sin(2 * M_PI * p->dist_hz * (t - p->dist_start)) : p->dist_amp;
}

static double drive_ref(const plant *s, double u)
{
    const plant_params *p = &s->p;
    double volts = u + p->offset + p->drift * s->t;
    return fabs(volts) <= p->deadband ? 0 : p->maxvel * volts / 10.0;
}

static void modes_outputs(plant *s, double ref, double f)
{
    const plant_params *p = &s->p;
    double am = p->lag > 0 ? (ref - s->vm) / p->lag : 0;
    s->xl = s->xm; s->vl = s->vm; s->al = am;
    for (int i = 0; i < 2; i++) {
        double w = mode_weight(p, i);
        if (w == 0) continue;
        double wn = 2 * M_PI * p->mode_hz[i];
        double acc = -wn * wn * s->d[i] - 2 * p->mode_zeta[i] * wn * s->dv[i] - am + f;
        s->xl += w * s->d[i];
        s->vl += w * s->dv[i];
        s->al += w * acc;
    }
}

static void modes_substep(plant *s, double u, double h)
{
    const plant_params *p = &s->p;
    double ref = drive_ref(s, u), f = s->force + disturbance(p, s->t + h / 2);
    if (p->lag <= 0 && ref != s->vm) {
        /* a speed step: the motor's impulse of acceleration kicks each mode */
        double dv = ref - s->vm;
        s->vm = ref;
        s->dv[0] -= dv; s->dv[1] -= dv;
    }
    if (s->c_h != h) modes_discretise(s, h);
    double z[ZU_N] = { s->vm, s->xm, s->d[0], s->dv[0], s->d[1], s->dv[1], ref, f }, n[Z_N];
    for (int i = 0; i < Z_N; i++) {
        double acc = 0;
        for (int j = 0; j < ZU_N; j++) if (j != Z_XM) acc += s->c_phi[i][j] * z[j];
        n[i] = i == Z_XM ? s->xm + acc : acc + s->c_phi[i][Z_XM] * s->xm;
    }
    s->vm = n[Z_VM]; s->xm = n[Z_XM];
    s->d[0] = n[Z_D1]; s->dv[0] = n[Z_D1V]; s->d[1] = n[Z_D2]; s->dv[1] = n[Z_D2V];
    s->t += h;
    modes_outputs(s, drive_ref(s, u), s->force + disturbance(p, s->t));
}

static void modes_step(plant *s, double u, double dt)
{
    int n = (int)ceil(dt / 1e-4 - 1e-9);
    if (n < 1) n = 1;
    if (n > 100000) n = 100000;
    for (int i = 0; i < n; i++) modes_substep(s, u, dt / n);
}

void plant_step(plant *s, int16_t dac, double dt)
{
    double u = dac * 10.0 / 32767.0, x0 = s->xl;
    s->zero = 0;
    if (dt <= 0) return;
    if (plant_has_modes(&s->p)) {
        modes_step(s, u, dt);
        zero_pulses(s, x0, s->xl);
        return;
    }
    /* sub-steps short against the resonance and the lag */
    double hmax = 1e-4;
    if (s->p.resonance > 0) { double h = 0.05 / s->p.resonance; if (h < hmax) hmax = h; }
    int n = (int)ceil(dt / hmax);
    if (n > 100000) n = 100000;
    double v0 = s->vl;
    for (int i = 0; i < n; i++) substep(s, u, dt / n);
    s->al = (s->vl - v0) / dt;   /* without modes: the step's mean acceleration */
    zero_pulses(s, x0, s->xl);
}

int32_t plant_counter(const plant *s)
{
    return (int32_t)(uint32_t)(int64_t)floor(s->xl);
}

int32_t plant_motor_counter(const plant *s)
{
    return (int32_t)(uint32_t)(int64_t)floor(s->xm);
}

int plant_cam(const plant *s)
{
    return s->p.cam_low <= s->p.cam_high && s->xl >= s->p.cam_low && s->xl <= s->p.cam_high;
}

void plant_master_init(plant_master *m, const plant_master_params *p)
{
    m->p = *p;
    m->t = 0;
    m->x = p->start;
}

void plant_master_step(plant_master *m, double dt)
{
    const double pi = 3.14159265358979323846;
    const plant_master_params *p = &m->p;
    m->t += dt;
    m->x = p->start + p->speed * m->t;
    if (p->speed_hz > 0)
        m->x += p->speed_amp / (2 * pi * p->speed_hz) * (1 - cos(2 * pi * p->speed_hz * m->t));
}

int32_t plant_master_counter(const plant_master *m)
{
    return (int32_t)(uint32_t)(int64_t)floor(m->x);
}

/* uniform in [-1, 1], xorshift64* */
static double marker_noise(plant_marker *m)
{
    m->rng ^= m->rng >> 12; m->rng ^= m->rng << 25; m->rng ^= m->rng >> 27;
    uint64_t r = m->rng * 2685821657736338717ULL;
    return (double)(r >> 11) / (double)(1ULL << 53) * 2 - 1;
}

static void marker_place(plant_marker *m)
{
    m->next = m->p.first + (double)m->k * m->p.pitch + m->p.noise * marker_noise(m);
}

void plant_marker_init(plant_marker *m, const plant_marker_params *p)
{
    memset(m, 0, sizeof *m);
    m->p = *p;
    m->rng = 0x9E3779B97F4A7C15ULL ^ p->seed;
    if (!m->rng) m->rng = 1;
    marker_place(m);
}

void plant_marker_step(plant_marker *m, double x0, double x1)
{
    m->on = 0;
    if (m->p.pitch <= 0) return;
    if (m->k == 0 && x0 > m->next + m->p.noise) {
        /* started beyond the first markers: the next one ahead */
        m->k = (uint32_t)ceil((x0 - m->p.first) / m->p.pitch);
        marker_place(m);
    }
    while (x1 > x0 && x0 < m->next && m->next <= x1) {
        m->latch = (int32_t)(uint32_t)(int64_t)floor(m->next);
        m->count++;
        m->on = 1;
        m->k++;
        marker_place(m);
    }
}

void plant_step_array(double *v, int16_t dac, double dt)
{
    plant s;
    plant_params p = {
        v[PA_MAXVEL], v[PA_LAG], v[PA_OFFSET], v[PA_DRIFT], v[PA_DEADBAND],
        v[PA_CPR], v[PA_ZOFF], v[PA_RES], v[PA_DAMP], v[PA_CAMLO], v[PA_CAMHI],
        v[PA_START],
        .mode_hz = { v[PA_M1HZ], v[PA_M2HZ] }, .mode_zeta = { v[PA_M1ZETA], v[PA_M2ZETA] },
        .mode_share = { v[PA_M1SHARE], v[PA_M2SHARE] },
    };
    if (v[PA_T] < 0) plant_init(&s, &p);
    else {
        s = (plant){ .p = p, .t = v[PA_T], .vm = v[PA_VM], .xm = v[PA_XM],
                     .vl = v[PA_VL], .xl = v[PA_XL], .latch = (int32_t)v[PA_LATCH],
                     .zeros = (uint32_t)v[PA_ZEROS],
                     .d = { v[PA_D1], v[PA_D2] }, .dv = { v[PA_D1V], v[PA_D2V] } };
    }
    s.force = v[PA_FORCE];
    plant_step(&s, dac, dt);
    v[PA_T] = s.t; v[PA_VM] = s.vm; v[PA_XM] = s.xm; v[PA_VL] = s.vl; v[PA_XL] = s.xl;
    v[PA_LATCH] = s.latch; v[PA_ZEROS] = s.zeros;
    v[PA_COUNTER] = plant_counter(&s); v[PA_ZERO] = s.zero; v[PA_CAM] = plant_cam(&s);
    v[PA_D1] = s.d[0]; v[PA_D1V] = s.dv[0]; v[PA_D2] = s.d[1]; v[PA_D2V] = s.dv[1];
    v[PA_MCOUNTER] = plant_motor_counter(&s); v[PA_ACC] = s.al;
}

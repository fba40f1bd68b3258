/*
** io_sim.c: the `sim` backend: up to SIM_AXES simulated axes (plant.h),
** each bound to located variables by [sim.axisN] sections. Without any
** such section one axis runs with the default bindings (docs/config.md).
** [sim.master] adds a master axis that runs by itself (or an encoder on
** one of the axes), [sim.marker0..3] marker sensors on the master or an
** axis: the plants of the CAM examples. [sim] clock = cycles runs the
** plants in the program's time (one task interval per scan executed), so
** that a loaded host, whose late scans skip cycles, sees the same motion.
*/
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "io_backend.h"
#include "../c_blocks/plant.h"

#define SIM_AXES 8

enum { B_DAC, B_COUNTER, B_LATCH, B_ZERO, B_CAM, B_ZCOUNT, B_MCOUNTER, B_LACC, NBIND };
static const char *bind_keys[NBIND] = { "dac", "counter", "latch", "zero", "cam", "zero_count",
                                        "motor_counter", "load_acc" };
static const char bind_size[NBIND] = { 'W', 'D', 'D', 'X', 'X', 'W', 'D', 'D' };
static const char *bind_default[NBIND] = { "%QW0", "%ID0", "%ID1", "%IX0.0", "%IX0.1", "", "", "" };

typedef struct sim_axis {
    int used;
    plant_params p;
    plant s;
    plc_loc loc[NBIND];
    int bound[NBIND];
    int16_t dac;
} sim_axis;

#define SIM_MARKERS 4

typedef struct sim_master {
    int used;
    plant_master_params p;
    plant_master m;
    int follow;           /* -1 own motion, else the axis whose load it measures */
    double ratio;         /* master counts per axis count, with follow */
    double x, x0;         /* position now and at the step before */
    plc_loc loc;
    int bound;
} sim_master;

enum { M_INPUT, M_LATCH, M_COUNT, NMBIND };
static const char *mbind_keys[NMBIND] = { "input", "latch", "count" };
static const char mbind_size[NMBIND] = { 'X', 'D', 'W' };

typedef struct sim_marker {
    int used;
    int on;               /* -1 the master, else an axis */
    plant_marker_params p;
    plant_marker m;
    plc_loc loc[NMBIND];
    int bound[NMBIND];
    double prev;          /* the axis's position at the step before */
} sim_marker;

typedef struct sim {
    sim_axis ax[SIM_AXES];
    sim_master master;
    sim_marker mk[SIM_MARKERS];
    int configured;       /* any [sim.axisN] seen */
    uint64_t last_ns;
    int started;
    int cycles;           /* [sim] clock = cycles: one tick per scan executed */
    uint64_t tick_ns;
} sim;

static void axis_defaults(sim_axis *a)
{
    memset(a, 0, sizeof *a);
    plant_defaults(&a->p);
    for (int i = 0; i < NBIND; i++)
        if (bind_default[i][0]) a->bound[i] = !plc_loc_parse(bind_default[i], &a->loc[i]);
}

static void *create(void)
{
    sim *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    axis_defaults(&s->ax[0]);
    s->ax[0].used = 1;
    return s;
}

static int num(const char *v, double *out)
{
    char *end;
    double x = strtod(v, &end);
    /* nan passes every range check and inf makes the plant nan: refused */
    if (end == v || *end || !isfinite(x)) return -1;
    *out = x;
    return 0;
}

/* an input address of the size wanted, into l */
static int bind_input(const char *v, char size, plc_loc *l, char *err, size_t n)
{
    if (plc_loc_parse(v, l)) { snprintf(err, n, "'%s' is not a located address inside the process image", v); return -1; }
    if (l->size != size) { snprintf(err, n, "'%s' must be a %%..%c address", v, size); return -1; }
    if (l->area == 'Q') { snprintf(err, n, "'%s' must be an input (%%I or %%M)", v); return -1; }
    return 0;
}

static int ranged(const char *v, double lo, double hi, double *out, char *err, size_t n)
{
    if (num(v, out) || *out < lo || *out > hi) {
        snprintf(err, n, "'%s' is not a number in %g..%g", v, lo, hi);
        return -1;
    }
    return 0;
}

static int axis_ref(const char *v, int *out, char *err, size_t n)
{
    unsigned idx;
    char tail;
    if (!strcmp(v, "master")) { *out = -1; return 0; }
    if (sscanf(v, "axis%u%c", &idx, &tail) == 1 && idx < SIM_AXES) { *out = (int)idx; return 0; }
    snprintf(err, n, "'%s': master or axis0 .. axis7", v);
    return -1;
}

static int config_master(sim_master *m, const char *key, const char *v, char *err, size_t n)
{
    if (!m->used) { m->used = 1; m->follow = -1; m->ratio = 1; }
    if (!strcmp(key, "counter")) { m->bound = !bind_input(v, 'D', &m->loc, err, n); return m->bound ? 0 : -1; }
    if (!strcmp(key, "follow")) {
        if (!*v) { m->follow = -1; return 0; }
        if (axis_ref(v, &m->follow, err, n)) return -1;
        if (m->follow < 0) { snprintf(err, n, "the master cannot follow itself"); return -1; }
        return 0;
    }
    double x;
    if (!strcmp(key, "speed")) return ranged(v, -1e9, 1e9, &m->p.speed, err, n);
    if (!strcmp(key, "speed_amp")) return ranged(v, -1e9, 1e9, &m->p.speed_amp, err, n);
    if (!strcmp(key, "speed_hz")) return ranged(v, 0, 1000, &m->p.speed_hz, err, n);
    if (!strcmp(key, "start")) return ranged(v, -2147483648.0, 2147483647.0, &m->p.start, err, n);
    if (!strcmp(key, "ratio")) {
        if (ranged(v, -1e6, 1e6, &x, err, n)) return -1;
        m->ratio = x;
        return 0;
    }
    snprintf(err, n, "unknown key");
    return -1;
}

static int config_marker(sim_marker *k, const char *key, const char *v, char *err, size_t n)
{
    if (!k->used) { k->used = 1; k->on = -1; }
    for (int i = 0; i < NMBIND; i++) {
        if (strcmp(key, mbind_keys[i])) continue;
        if (!*v) { k->bound[i] = 0; return 0; }
        if (bind_input(v, mbind_size[i], &k->loc[i], err, n)) return -1;
        k->bound[i] = 1;
        return 0;
    }
    if (!strcmp(key, "on")) return axis_ref(v, &k->on, err, n);
    if (!strcmp(key, "first")) return ranged(v, -2147483648.0, 2147483647.0, &k->p.first, err, n);
    if (!strcmp(key, "pitch")) return ranged(v, 0, 2147483647.0, &k->p.pitch, err, n);
    if (!strcmp(key, "noise")) return ranged(v, 0, 1e9, &k->p.noise, err, n);
    if (!strcmp(key, "seed")) {
        double x;
        if (ranged(v, 0, 4294967295.0, &x, err, n)) return -1;
        k->p.seed = (uint32_t)x;
        return 0;
    }
    snprintf(err, n, "unknown key");
    return -1;
}

static int config(void *st, const char *sec, const char *key, const char *v, char *err, size_t n)
{
    sim *s = st;
    unsigned idx;
    char tail;
    if (!strcmp(sec, "sim.master")) return config_master(&s->master, key, v, err, n);
    if (sscanf(sec, "sim.marker%u%c", &idx, &tail) == 1) {
        if (idx >= SIM_MARKERS) { snprintf(err, n, "unknown section (markers are [sim.marker0] .. [sim.marker3])"); return -1; }
        return config_marker(&s->mk[idx], key, v, err, n);
    }
    if (!strcmp(sec, "sim")) {
        if (!strcmp(key, "clock")) {
            if (!strcmp(v, "plc") || !strcmp(v, "cycles")) { s->cycles = !strcmp(v, "cycles"); return 0; }
            snprintf(err, n, "'%s': plc (the plant moves on by the PLC time, missed cycles too) "
                     "or cycles (one task interval per scan executed)", v);
            return -1;
        }
        snprintf(err, n, "unknown key (clock; axes are [sim.axis0] .. [sim.axis7])");
        return -1;
    }
    if (sscanf(sec, "sim.axis%u%c", &idx, &tail) != 1 || idx >= SIM_AXES) {
        snprintf(err, n, "unknown section (axes are [sim.axis0] .. [sim.axis7])");
        return -1;
    }
    if (!s->configured) { s->configured = 1; s->ax[0].used = 0; }
    sim_axis *a = &s->ax[idx];
    if (!a->used) { axis_defaults(a); a->used = 1; for (int i = 0; i < NBIND; i++) a->bound[i] = 0; }
    for (int i = 0; i < NBIND; i++) {
        if (strcmp(key, bind_keys[i])) continue;
        if (!*v) { a->bound[i] = 0; return 0; }
        plc_loc l;
        if (plc_loc_parse(v, &l)) { snprintf(err, n, "'%s' is not a located address inside the process image", v); return -1; }
        if (l.size != bind_size[i]) { snprintf(err, n, "'%s' must be a %%..%c address", v, bind_size[i]); return -1; }
        if (i == B_DAC ? l.area == 'I' : l.area == 'Q') {
            snprintf(err, n, "'%s': %s must be %s", v, key, i == B_DAC ? "an output (%Q or %M)" : "an input (%I or %M)");
            return -1;
        }
        a->loc[i] = l;
        a->bound[i] = 1;
        return 0;
    }
    static const struct { const char *k; size_t off; double lo, hi; } pk[] = {
#define P(k, f, lo, hi) { k, offsetof(plant_params, f), lo, hi }
        P("maxvel", maxvel, 0, 1e9), P("lag", lag, 0, 100), P("offset", offset, -10, 10),
        P("drift", drift, -10, 10), P("deadband", deadband, 0, 10),
        P("counts_per_rev", counts_per_rev, 0, 1e9), P("zero_offset", zero_offset, -1e9, 1e9),
        P("resonance", resonance, 0, 10000), P("damping", damping, 0, 100),
        P("cam_low", cam_low, -2147483648.0, 2147483647.0),
        P("cam_high", cam_high, -2147483648.0, 2147483647.0),
        P("start", start, -2147483648.0, 2147483647.0),
        P("mode1_hz", mode_hz[0], 0, 10000), P("mode1_zeta", mode_zeta[0], 0, 0.999),
        P("mode1_share", mode_share[0], 1e-6, 1e6),
        P("mode2_hz", mode_hz[1], 0, 10000), P("mode2_zeta", mode_zeta[1], 0, 0.999),
        P("mode2_share", mode_share[1], 1e-6, 1e6),
        P("dist_amp", dist_amp, -1e12, 1e12), P("dist_hz", dist_hz, 0, 10000),
        P("dist_start", dist_start, 0, 1e9),
#undef P
    };
    for (size_t i = 0; i < sizeof pk / sizeof pk[0]; i++) {
        if (strcmp(key, pk[i].k)) continue;
        double x;
        if (num(v, &x) || x < pk[i].lo || x > pk[i].hi) {
            snprintf(err, n, "'%s' is not a number in %g..%g", v, pk[i].lo, pk[i].hi);
            return -1;
        }
        *(double *)((char *)&a->p + pk[i].off) = x;
        if (plant_has_modes(&a->p) && a->p.resonance > 0) {
            snprintf(err, n, "resonance and mode1_hz/mode2_hz exclude each other "
                     "(the elastic modes replace the legacy resonance)");
            return -1;
        }
        return 0;
    }
    snprintf(err, n, "unknown key");
    return -1;
}

/* Every signal the plant writes into the image in a place of its own: two
** axes copied from one section, say, would both write one counter and each
** position loop would follow the other's encoder. (Two axes may read one
** DAC: two drives on one speed reference.) 0, or -1 naming both. */
static int list_inputs(void *st, plc_image *img, io_input_use *in, int max)
{
    sim *s = st;
    int k = 0;
    for (int i = 0; i < SIM_AXES; i++)
        for (int b = B_COUNTER; b < NBIND && s->ax[i].used; b++)
            if (s->ax[i].bound[b] && k < max) {
                in[k].p = plc_loc_ptr(img, &s->ax[i].loc[b]);
                in[k].w = plc_loc_width(&s->ax[i].loc[b]);
                snprintf(in[k++].who, sizeof in[0].who, "[sim.axis%d] %s", i, bind_keys[b]);
            }
    if (s->master.used && s->master.bound && k < max) {
        in[k].p = plc_loc_ptr(img, &s->master.loc);
        in[k].w = plc_loc_width(&s->master.loc);
        snprintf(in[k++].who, sizeof in[0].who, "[sim.master] counter");
    }
    for (int i = 0; i < SIM_MARKERS; i++)
        for (int b = 0; b < NMBIND && s->mk[i].used; b++)
            if (s->mk[i].bound[b] && k < max) {
                in[k].p = plc_loc_ptr(img, &s->mk[i].loc[b]);
                in[k].w = plc_loc_width(&s->mk[i].loc[b]);
                snprintf(in[k++].who, sizeof in[0].who, "[sim.marker%d] %s", i, mbind_keys[b]);
            }
    return k;
}

static int inputs_apart(sim *s, plc_image *img, char *err, size_t n)
{
    io_input_use in[SIM_AXES * NBIND + 1 + SIM_MARKERS * NMBIND];
    return io_inputs_apart(in, list_inputs(s, img, in, (int)(sizeof in / sizeof in[0])), err, n);
}

static int open_(void *st, plc_image *img, uint64_t tick, char *err, size_t n)
{
    sim *s = st;
    s->tick_ns = tick;
    for (int i = 0; i < SIM_AXES; i++) {
        sim_axis *a = &s->ax[i];
        if (!a->used) continue;
        if (!a->bound[B_DAC] || !a->bound[B_COUNTER]) {
            snprintf(err, n, "[sim.axis%d]: dac and counter must be set", i);
            return -1;
        }
        if (plant_has_modes(&a->p) && a->p.resonance > 0) {
            snprintf(err, n, "[sim.axis%d]: resonance and mode1_hz/mode2_hz exclude each other "
                     "(the elastic modes replace the legacy resonance)", i);
            return -1;
        }
        plant_init(&a->s, &a->p);
    }
    sim_master *m = &s->master;
    if (m->used) {
        if (!m->bound) { snprintf(err, n, "[sim.master]: counter must be set"); return -1; }
        if (m->follow >= 0 && !s->ax[m->follow].used) {
            snprintf(err, n, "[sim.master]: follow = axis%d, an axis not simulated", m->follow);
            return -1;
        }
        plant_master_init(&m->m, &m->p);
    }
    for (int i = 0; i < SIM_MARKERS; i++) {
        sim_marker *k = &s->mk[i];
        if (!k->used) continue;
        if (k->on < 0 ? !m->used : !s->ax[k->on].used) {
            if (k->on < 0) snprintf(err, n, "[sim.marker%d]: on = master, and no [sim.master]", i);
            else snprintf(err, n, "[sim.marker%d]: on = axis%d, an axis not simulated", i, k->on);
            return -1;
        }
        if (k->p.pitch <= 0) { snprintf(err, n, "[sim.marker%d]: pitch must be set (> 0)", i); return -1; }
        if (k->p.noise >= k->p.pitch / 2) {
            snprintf(err, n, "[sim.marker%d]: noise must be below half the pitch", i);
            return -1;
        }
        plant_marker_init(&k->m, &k->p);
    }
    s->started = 0;
    return inputs_apart(s, img, err, n);
}

/* counts/s^2 rounded, saturated to DINT */
static int32_t acc_dint(double a)
{
    if (a != a) return 0;
    if (a >= 2147483647.0) return INT32_MAX;
    if (a <= -2147483648.0) return INT32_MIN;
    return (int32_t)lround(a);
}

static int rd(void *st, plc_image *img, uint64_t now)
{
    sim *s = st;
    /* clock = cycles: a scan that came too late skipped cycles of PLC time,
    ** the plant skips none (it runs in lockstep with the program) */
    double dt = !s->started ? 0 : s->cycles ? s->tick_ns * 1e-9 : (now - s->last_ns) * 1e-9;
    s->started = 1;
    s->last_ns = now;
    for (int i = 0; i < SIM_AXES; i++) {
        sim_axis *a = &s->ax[i];
        if (!a->used) continue;
        plant_step(&a->s, a->dac, dt);
        img_set32(plc_loc_ptr(img, &a->loc[B_COUNTER]), 0, plant_counter(&a->s));
        if (a->bound[B_LATCH]) img_set32(plc_loc_ptr(img, &a->loc[B_LATCH]), 0, a->s.latch);
        if (a->bound[B_ZERO]) *plc_loc_ptr(img, &a->loc[B_ZERO]) = (uint8_t)a->s.zero;
        if (a->bound[B_CAM]) *plc_loc_ptr(img, &a->loc[B_CAM]) = (uint8_t)plant_cam(&a->s);
        if (a->bound[B_ZCOUNT]) img_set16(plc_loc_ptr(img, &a->loc[B_ZCOUNT]), 0, (int16_t)(uint16_t)a->s.zeros);
        if (a->bound[B_MCOUNTER]) img_set32(plc_loc_ptr(img, &a->loc[B_MCOUNTER]), 0, plant_motor_counter(&a->s));
        if (a->bound[B_LACC]) img_set32(plc_loc_ptr(img, &a->loc[B_LACC]), 0, acc_dint(a->s.al));
    }
    sim_master *m = &s->master;
    if (m->used) {
        m->x0 = m->x;
        if (m->follow >= 0) {
            m->x = m->p.start + m->ratio * s->ax[m->follow].s.xl;
        } else {
            plant_master_step(&m->m, dt);
            m->x = m->m.x;
        }
        if (dt == 0) m->x0 = m->x;
        img_set32(plc_loc_ptr(img, &m->loc), 0, (int32_t)(uint32_t)(int64_t)floor(m->x));
    }
    for (int i = 0; i < SIM_MARKERS; i++) {
        sim_marker *k = &s->mk[i];
        if (!k->used) continue;
        if (k->on < 0) {
            plant_marker_step(&k->m, m->x0, m->x);
        } else {
            /* the axis's load position before and after this step */
            double x1 = s->ax[k->on].s.xl;
            plant_marker_step(&k->m, dt == 0 ? x1 : k->prev, x1);
            k->prev = x1;
        }
        if (k->bound[M_INPUT]) *plc_loc_ptr(img, &k->loc[M_INPUT]) = (uint8_t)k->m.on;
        if (k->bound[M_LATCH]) img_set32(plc_loc_ptr(img, &k->loc[M_LATCH]), 0, k->m.latch);
        if (k->bound[M_COUNT]) img_set16(plc_loc_ptr(img, &k->loc[M_COUNT]), 0, (int16_t)(uint16_t)k->m.count);
    }
    return 0;
}

static int wr(void *st, const plc_image *img)
{
    sim *s = st;
    for (int i = 0; i < SIM_AXES; i++)
        if (s->ax[i].used)
            s->ax[i].dac = img_get16(plc_loc_ptr((plc_image *)img, &s->ax[i].loc[B_DAC]), 0);
    return 0;
}

static void safe(void *st, plc_image *img)
{
    sim *s = st;
    (void)img;
    for (int i = 0; i < SIM_AXES; i++) s->ax[i].dac = 0;
}

static void close_(void *st) { free(st); }

/* Per axis: position (counts) and speed (counts/s), 32-bit, high word first. */
static size_t diag(void *st, uint16_t *r, size_t max)
{
    sim *s = st;
    size_t n = 0;
    for (int i = 0; i < SIM_AXES && n + 4 <= max; i++) {
        int32_t pos = plant_counter(&s->ax[i].s), vel = (int32_t)s->ax[i].s.vl;
        if (!s->ax[i].used) pos = vel = 0;
        r[n++] = (uint16_t)((uint32_t)pos >> 16); r[n++] = (uint16_t)pos;
        r[n++] = (uint16_t)((uint32_t)vel >> 16); r[n++] = (uint16_t)vel;
    }
    return n;
}

const io_backend_ops io_sim = {
    "sim", create, config, open_, rd, wr, safe, close_, diag, list_inputs
};

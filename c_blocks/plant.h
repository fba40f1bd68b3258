/*
** plant.h: the simulated plant of one axis.
**
**   DAC (16-bit signed, 32767 = +10 V)
**     -> drive: speed reference = maxvel * (V + offset) / 10 V, zero inside
**        the dead band, first-order lag; offset drifts at `drift` V/s
**     -> motor; load coupled rigidly or, with resonance > 0, through a
**        spring and damper (two-mass system, natural frequency `resonance`
**        Hz, damping ratio `damping`)
**     -> encoder on the load: counts x4 (int32, wraps), a zero pulse once
**        per revolution at position = zero_offset + k * counts_per_rev,
**        the count latched exactly there
**     -> home cam: on while cam_low <= position <= cam_high.
**
** Elastic modes (mode_hz[0..1] > 0; then `resonance` is not used): the
** load is coupled to the motor through up to two modes, each a natural
** frequency and a damping ratio. The load is split into parallel partial
** masses in the ratio of mode_share; mode i's deflection d_i = x_load_i - x_m
** obeys d_i'' + 2 zeta_i w_i d_i' + w_i^2 d_i = -a_motor + f, f = force on
** the load / load mass (counts/s^2: the input `force` plus the disturbance
** generator). The load position is x_m + sum w_i d_i (w_i = normalised
** shares), its acceleration what an accelerometer on the load shows. The
** drive stays an ideal speed source: the motor ignores the load's reaction.
** The linear part is integrated exactly (matrix exponential with the inputs
** held over each sub-step), so frequencies and decays are the parameters'.
** A motor encoder (plant_motor_counter) sits beside the load encoder.
**
** Units: counts and seconds. Used by the `sim` I/O backend and, through
** the double-array form below, by the ST block SIM_AXIS (c_blocks/).
*/
#ifndef PLANT_H
#define PLANT_H

#include <stdint.h>

/* C linkage when included from C++ (OpenPLC v3 builds the PLC program with
** g++); plant.c itself is always compiled as C. */
#ifdef __cplusplus
extern "C" {
#endif

typedef struct plant_params {
    double maxvel;        /* counts/s at +10 V */
    double lag;           /* s, drive time constant (0 = none) */
    double offset;        /* V, drive offset at t = 0 */
    double drift;         /* V/s, offset drift */
    double deadband;      /* V, |V + offset| below it gives no speed */
    double counts_per_rev;
    double zero_offset;   /* counts, position of the first zero pulse */
    double resonance;     /* Hz, 0 = rigid */
    double damping;       /* ratio */
    double cam_low, cam_high;   /* counts; cam_low > cam_high = no cam */
    double start;         /* counts, initial position */
    /* elastic modes (0 Hz = absent); any present replaces `resonance` */
    double mode_hz[2];    /* Hz, natural (undamped) frequency */
    double mode_zeta[2];  /* damping ratio, 0 <= zeta < 1 */
    double mode_share[2]; /* share of the load mass in the mode (normalised) */
    /* disturbance on the load, counts/s^2 (force / load mass), from dist_start s:
    ** dist_amp constant (dist_hz 0) or dist_amp sin(2 pi dist_hz (t - dist_start)) */
    double dist_amp, dist_hz, dist_start;
} plant_params;

typedef struct plant {
    plant_params p;
    double t;             /* s since start */
    double vm, xm;        /* motor speed (counts/s), position (counts) */
    double vl, xl;        /* load */
    int32_t latch;        /* count at the last zero pulse */
    uint32_t zeros;       /* zero pulses so far */
    int zero;             /* a zero pulse during the last step */
    /* elastic modes */
    double force;         /* counts/s^2: force on the load / load mass, set by the caller */
    double d[2], dv[2];   /* modal deflections (counts) and their speeds */
    double al;            /* load acceleration at the end of the last step */
    double c_h;           /* sub-step of the cached discretisation (0 = none) */
    double c_phi[6][8];   /* [state | input] -> next state over c_h */
} plant;

void plant_defaults(plant_params *p);
void plant_init(plant *s, const plant_params *p);
/* Advance by dt seconds with the DAC at dac. */
void plant_step(plant *s, int16_t dac, double dt);
int32_t plant_counter(const plant *s);           /* load encoder */
int32_t plant_motor_counter(const plant *s);     /* motor encoder */
/* Whether the elastic modes (not the legacy `resonance`) are in use. */
int plant_has_modes(const plant_params *p);
int plant_cam(const plant *s);

/* Master axis: a position that runs by itself, with no drive (a line shaft,
** a conveyor at its own speed): x(t) = start + speed t
** + speed_amp / (2 pi speed_hz) (1 - cos(2 pi speed_hz t)), i.e. the speed
** speed + speed_amp sin(2 pi speed_hz t) counts/s (speed_hz 0: constant).
** Computed from t in closed form, so no error accumulates. */
typedef struct plant_master_params {
    double speed, speed_amp, speed_hz, start;
} plant_master_params;
typedef struct plant_master {
    plant_master_params p;
    double t, x;
} plant_master;
void plant_master_init(plant_master *m, const plant_master_params *p);
void plant_master_step(plant_master *m, double dt);
int32_t plant_master_counter(const plant_master *m);

/* Marker sensor: a digital input that pulses once per product (cycle) as
** the position it watches passes first + k pitch + e_k forwards, e_k drawn
** uniformly in [-noise, +noise] (a deterministic generator from `seed`).
** The count there is latched, as the encoder latches the zero pulse, so
** the marker's position is exact in the latch even when the pulse is seen
** a cycle late. Markers passed backwards are not seen, and each marker
** pulses once (a product passing the sensor again is not counted again). */
typedef struct plant_marker_params {
    double first, pitch, noise;   /* counts */
    uint32_t seed;
} plant_marker_params;
typedef struct plant_marker {
    plant_marker_params p;
    uint64_t rng;
    uint32_t k;           /* index of the next marker */
    double next;          /* its position, noise included */
    int32_t latch;        /* count at the last marker */
    uint32_t count;       /* markers so far */
    int on;               /* a marker during the last step */
} plant_marker;
void plant_marker_init(plant_marker *m, const plant_marker_params *p);
/* The watched position moved from x0 to x1 in the last step. */
void plant_marker_step(plant_marker *m, double x0, double x1);

/* The same model on a flat array, for C bodies of ST blocks (no structs
** cross the ST/C boundary). Indices are fixed: */
enum {
    PA_MAXVEL, PA_LAG, PA_OFFSET, PA_DRIFT, PA_DEADBAND, PA_CPR, PA_ZOFF,
    PA_RES, PA_DAMP, PA_CAMLO, PA_CAMHI, PA_START,        /* parameters */
    PA_T, PA_VM, PA_XM, PA_VL, PA_XL, PA_LATCH, PA_ZEROS, /* state */
    PA_COUNTER, PA_ZERO, PA_CAM,                          /* outputs */
    PA_M1HZ, PA_M1ZETA, PA_M1SHARE, PA_M2HZ, PA_M2ZETA, PA_M2SHARE,
    PA_FORCE,                                             /* modes, input */
    PA_D1, PA_D1V, PA_D2, PA_D2V,                         /* modal state */
    PA_MCOUNTER, PA_ACC,                                  /* motor counter, load acc. */
    PA_N
};
/* v[PA_T] < 0 means "not started": the state is initialised first. */
void plant_step_array(double *v, int16_t dac, double dt);

#ifdef __cplusplus
}
#endif

#endif

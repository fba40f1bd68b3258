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
} plant_params;

typedef struct plant {
    plant_params p;
    double t;             /* s since start */
    double vm, xm;        /* motor speed (counts/s), position (counts) */
    double vl, xl;        /* load */
    int32_t latch;        /* count at the last zero pulse */
    uint32_t zeros;       /* zero pulses so far */
    int zero;             /* a zero pulse during the last step */
} plant;

void plant_defaults(plant_params *p);
void plant_init(plant *s, const plant_params *p);
/* Advance by dt seconds with the DAC at dac. */
void plant_step(plant *s, int16_t dac, double dt);
int32_t plant_counter(const plant *s);
int plant_cam(const plant *s);

/* The same model on a flat array, for C bodies of ST blocks (no structs
** cross the ST/C boundary). Indices are fixed: */
enum {
    PA_MAXVEL, PA_LAG, PA_OFFSET, PA_DRIFT, PA_DEADBAND, PA_CPR, PA_ZOFF,
    PA_RES, PA_DAMP, PA_CAMLO, PA_CAMHI, PA_START,        /* parameters */
    PA_T, PA_VM, PA_XM, PA_VL, PA_XL, PA_LATCH, PA_ZEROS, /* state */
    PA_COUNTER, PA_ZERO, PA_CAM,                          /* outputs */
    PA_N
};
/* v[PA_T] < 0 means "not started": the state is initialised first. */
void plant_step_array(double *v, int16_t dac, double dt);

#ifdef __cplusplus
}
#endif

#endif

/* SIM_AXIS, the plant as an ST block, against the hand-computed response
** and against the sim backend fed the same DAC: the same model, count for
** count. */
#include <check.h>
#include <math.h>
#include <string.h>
#include "io_backend.h"
#include "program.h"
#include "../common/check_run.h"

extern const io_backend_ops io_sim;

static void *var(const char *path)
{
    const plc_var *v = plc_var_find(&plc_program_linked, path);
    ck_assert_msg(v != NULL, "%s missing", path);
    return plc_var_addr(v);
}

START_TEST(block_matches_backend)
{
    char err[200];
    plc_program_linked.init();
    void *st = io_sim.create();
    ck_assert_int_eq(io_sim.config(st, "sim.axis0", "zero_offset", "123", err, sizeof err), 0);
    ck_assert_int_eq(io_sim.config(st, "sim.axis0", "dac", "%QW0", err, sizeof err), 0);
    ck_assert_int_eq(io_sim.config(st, "sim.axis0", "counter", "%ID0", err, sizeof err), 0);
    ck_assert_int_eq(io_sim.config(st, "sim.axis0", "latch", "%ID1", err, sizeof err), 0);
    ck_assert_int_eq(io_sim.open(st, &plc_img, 1000000, err, sizeof err), 0);
    int32_t *counter = var("CONFIG0.RES0.INST0.AX.COUNTER"), *latch = var("CONFIG0.RES0.INST0.AX.LATCH");
    uint32_t *zeros = var("CONFIG0.RES0.INST0.AX.ZEROS");
    img_set16(plc_img.qw, 0, 16384);
    io_sim.read_inputs(st, &plc_img, 0);        /* PLC time starts */
    for (unsigned long k = 0; k < 1000; k++) {
        plc_program_linked.run(k);
        io_sim.write_outputs(st, &plc_img);
        io_sim.read_inputs(st, &plc_img, (k + 1) * 1000000);
        ck_assert_int_eq(*counter, img_get32(plc_img.id, 0));
    }
    /* x(1 s) = 50001.5 counts/s * (1 s - 0.005 s), the default lag = 49751.5 */
    ck_assert_msg(fabs(*counter - 49751.5) <= 5, "counter %d", *counter);
    ck_assert_int_eq(*latch, 48123);
    ck_assert_int_eq(img_get32(plc_img.id, 1), 48123);
    ck_assert_uint_eq(*zeros, 13);
    io_sim.close(st);
}
END_TEST

/* the elastic modes through the block's inputs and outputs, against the
** backend configured alike (the force as a constant disturbance from 0 s) */
START_TEST(modes_block_matches_backend)
{
    char err[200];
    plc_program_linked.init();
    void *st = io_sim.create();
    static const char *kv[][2] = {
        { "dac", "%QW0" }, { "counter", "%ID10" }, { "motor_counter", "%ID11" }, { "load_acc", "%ID12" },
        { "mode1_hz", "53" }, { "mode1_zeta", "0.05" }, { "mode2_hz", "11" }, { "mode2_zeta", "0.3" },
        { "mode2_share", "3" }, { "dist_amp", "100000" }, { "dist_start", "0" },
    };
    for (size_t i = 0; i < sizeof kv / sizeof kv[0]; i++)
        ck_assert_msg(io_sim.config(st, "sim.axis0", kv[i][0], kv[i][1], err, sizeof err) == 0, "%s", err);
    ck_assert_int_eq(io_sim.open(st, &plc_img, 1000000, err, sizeof err), 0);
    int32_t *counter = var("CONFIG0.RES0.INST0.AX2.COUNTER"), *mcounter = var("CONFIG0.RES0.INST0.AX2.MCOUNTER");
    double *acc = var("CONFIG0.RES0.INST0.AX2.ACC"), *pos = var("CONFIG0.RES0.INST0.AX2.POS");
    double *mpos = var("CONFIG0.RES0.INST0.AX2.MPOS");
    img_set16(plc_img.qw, 0, 16384);
    io_sim.read_inputs(st, &plc_img, 0);
    int differ = 0;
    for (unsigned long k = 0; k < 1000; k++) {
        plc_program_linked.run(k);
        io_sim.write_outputs(st, &plc_img);
        io_sim.read_inputs(st, &plc_img, (k + 1) * 1000000);
        ck_assert_int_eq(*counter, img_get32(plc_img.id, 10));
        ck_assert_int_eq(*mcounter, img_get32(plc_img.id, 11));
        ck_assert_int_eq(lround(*acc), img_get32(plc_img.id, 12));
        if (*counter != *mcounter) differ++;
    }
    /* the load lags the motor by the modes' static deflection under the force
    ** F/w^2 shares: 1e5 (0.25/(2 pi 53)^2 + 0.75/(2 pi 11)^2) = 15.9 counts ahead */
    double dstat = 1e5 * (0.25 / pow(2 * M_PI * 53, 2) + 0.75 / pow(2 * M_PI * 11, 2));
    ck_assert_msg(fabs(*pos - *mpos - dstat) < 0.05, "load - motor %g, expected %g", *pos - *mpos, dstat);
    ck_assert_int_gt(differ, 900);
    io_sim.close(st);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("sim_block");
    TCase *t = tcase_create("st");
    tcase_add_test(t, block_matches_backend);
    tcase_add_test(t, modes_block_matches_backend);
    suite_add_tcase(s, t);
    return check_run(s);
}

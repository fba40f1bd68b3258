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

int main(void)
{
    Suite *s = suite_create("sim_block");
    TCase *t = tcase_create("st");
    tcase_add_test(t, block_matches_backend);
    suite_add_tcase(s, t);
    return check_run(s);
}

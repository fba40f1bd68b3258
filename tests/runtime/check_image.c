/* Image binding: the compiled test program (st/iotest.st) reads and
** writes the process image at the last address of every area. */
#include <check.h>
#include "plc_image.h"
#include "program.h"
#include "../common/check_run.h"

static void run(void) { plc_program_linked.run(0); }

START_TEST(last_addresses)
{
    plc_program_linked.init();
    plc_img.ix[1023 * 8 + 7] = 1;
    plc_img.ib[1023] = 0xA5;
    img_set16(plc_img.iw, 0, -7);
    img_set16(plc_img.iw, 1023, 12345);
    img_set32(plc_img.id, 1023, -100000);
    img_set64(plc_img.il, 1023, 1LL << 40);
    img_set16(plc_img.mw, 10, 99);
    run();
    ck_assert_uint_eq(plc_img.qx[1023 * 8 + 7], 1);
    ck_assert_uint_eq(plc_img.mx[1023 * 8 + 7], 0);
    ck_assert_uint_eq(plc_img.qb[1023], 0xA5);
    ck_assert_int_eq(img_get16(plc_img.qw, 100), -7);
    ck_assert_int_eq(img_get16(plc_img.qw, 1023), 12345);
    ck_assert_int_eq(img_get32(plc_img.qd, 1023), -100000);
    ck_assert(img_get64(plc_img.ql, 1023) == (1LL << 40));
    ck_assert_int_eq(img_get32(plc_img.md, 1023), -99999);
    ck_assert(img_get64(plc_img.ml, 1023) == (1LL << 40) + 1);
    ck_assert_int_eq(img_get16(plc_img.qw, 200), 100);
    /* nothing else of the output areas was touched */
    for (int i = 0; i < 1023 * 8 + 7; i++) ck_assert_uint_eq(plc_img.qx[i], 0);
    for (int i = 0; i < 100; i++) ck_assert_int_eq(img_get16(plc_img.qw, (unsigned)i), 0);
}
END_TEST

START_TEST(variable_table)
{
    plc_program_linked.init();
    const plc_var *k = plc_var_find(&plc_program_linked, "CONFIG0.RES0.INST0.KEEP");
    ck_assert_ptr_nonnull(k);
    ck_assert_str_eq(k->type, "DINT");
    ck_assert_uint_eq(k->retain, 1);
    ck_assert_int_eq(*(int32_t *)plc_var_addr(k), 42);
    const plc_var *q = plc_var_find(&plc_program_linked, "CONFIG0.RES0.INST0.QW_LAST");
    ck_assert_ptr_nonnull(q);
    ck_assert_uint_eq(q->retain, 0);
    ck_assert_ptr_eq(plc_var_addr(q), plc_img.qw + 2 * 1023);   /* located: the image itself */
    ck_assert_ptr_null(plc_var_find(&plc_program_linked, "CONFIG0.RES0.INST0.NOPE"));
    ck_assert_uint_eq(*plc_program_linked.ticktime, 20000000);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("image");
    TCase *t = tcase_create("binding");
    tcase_add_test(t, last_addresses);
    tcase_add_test(t, variable_table);
    suite_add_tcase(s, t);
    return check_run(s);
}

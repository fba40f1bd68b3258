/* The EDS/DCF reader (plc_runtime/canopen/eds.c) on the example drive's DCF
 * (examples/cia402/drive402.eds, expected values read off the file by hand)
 * and on broken files, each of which must give one message naming the file,
 * the line or the object, and what is wrong. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "eds.h"

static const char *dir;      /* a folder for the broken files (argv[1]) */

static const char *write_file(const char *name, const char *text)
{
    static char path[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
    return path;
}

#define HEAD "[FileInfo]\nFileName=x.eds\n[1000]\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x191\n"

static void expect_error(const char *text, const char *what1, const char *what2)
{
    eds_info e;
    char err[400];
    const char *p = write_file("bad.eds", text);
    ck_assert_int_eq(eds_load(p, 7, &e, err, sizeof err), -1);
    ck_assert_msg(strstr(err, p) && strstr(err, what1) && (!what2 || strstr(err, what2)),
                  "message '%s' lacks '%s' / '%s'", err, what1, what2 ? what2 : "");
}

START_TEST(example_drive_dcf)
{
    eds_info e;
    char err[400];
    ck_assert_msg(eds_load("examples/cia402/drive402.eds", 5, &e, err, sizeof err) == 0, "%s", err);
    ck_assert(e.has_device_type);
    ck_assert_uint_eq(e.device_type, 0x00020192);
    ck_assert(e.has_pdo);
    /* RPDO1: controlword 16, mode 8, target position 32 bits */
    ck_assert_uint_eq(e.rpdo[0].n, 3);
    ck_assert_uint_eq(e.rpdo[0].e[0].index, 0x6040);
    ck_assert_uint_eq(e.rpdo[0].e[0].bits, 16);
    ck_assert_uint_eq(e.rpdo[0].e[1].index, 0x6060);
    ck_assert_uint_eq(e.rpdo[0].e[1].bits, 8);
    ck_assert_uint_eq(e.rpdo[0].e[2].index, 0x607A);
    ck_assert_uint_eq(e.rpdo[0].e[2].bits, 32);
    ck_assert_uint_eq(e.rpdo[1].n, 1);
    ck_assert_uint_eq(e.rpdo[1].e[0].index, 0x60FF);
    ck_assert_uint_eq(e.rpdo[2].n, 0);
    /* TPDO2: velocity actual 32, error code 16 */
    ck_assert_uint_eq(e.tpdo[0].n, 3);
    ck_assert_uint_eq(e.tpdo[1].n, 2);
    ck_assert_uint_eq(e.tpdo[1].e[0].index, 0x606C);
    ck_assert_uint_eq(e.tpdo[1].e[1].index, 0x603F);
    ck_assert_uint_eq(e.tpdo[1].e[1].bits, 16);
    ck_assert_uint_eq(e.tpdo[0].trans, 1);        /* ParameterValue 1 over DefaultValue 255 */
    /* start-up writes: the ParameterValues of writable objects outside the PDO area */
    ck_assert_int_eq(e.nwrites, 3);
    ck_assert_uint_eq(e.w[0].index, 0x605A);
    ck_assert_uint_eq(e.w[0].size, 2);
    ck_assert_uint_eq(e.w[0].value, 2);
    ck_assert_uint_eq(e.w[1].index, 0x6065);
    ck_assert_uint_eq(e.w[1].size, 4);
    ck_assert_uint_eq(e.w[1].value, 2000);
    ck_assert_uint_eq(e.w[2].index, 0x6098);
    ck_assert_uint_eq(e.w[2].size, 1);
    ck_assert_uint_eq(e.w[2].value, 35);
}
END_TEST

START_TEST(nodeid_values_and_signed_writes)
{
    eds_info e;
    char err[400];
    const char *p = write_file("ok.eds", HEAD
        "[1800sub1]\nDataType=0x0007\nAccessType=rw\nDefaultValue=0x180+$NODEID\n"
        "[1A00sub0]\nDataType=0x0005\nAccessType=rw\nParameterValue=1\n"
        "[1A00sub1]\nDataType=0x0007\nAccessType=rw\nParameterValue=0x60000108\n"
        "[2000]\nDataType=0x0003\nAccessType=rw\nParameterValue=-2\n"
        "[2001]\nDataType=0x0005\nAccessType=ro\nParameterValue=9\n");
    ck_assert_msg(eds_load(p, 7, &e, err, sizeof err) == 0, "%s", err);
    ck_assert_uint_eq(e.tpdo[0].n, 1);
    ck_assert_uint_eq(e.tpdo[0].e[0].sub, 1);
    ck_assert_int_eq(e.nwrites, 1);                 /* 0x2001 is read-only */
    ck_assert_uint_eq(e.w[0].value, 0xFFFE);        /* -2 as INTEGER16 */
}
END_TEST

START_TEST(bad_files_named)
{
    eds_info e;
    char err[400];
    ck_assert_int_eq(eds_load("no/such/drive.eds", 7, &e, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "no/such/drive.eds: No such file"));
    expect_error("[FileInfo]\nFileName=x\nthis line is garbled\n", ":3: not an EDS/DCF line", NULL);
    expect_error("[FileInfo]\nFileName=x\n[2000]\nDefaultValue=1\n", "no object 0x1000", NULL);
    expect_error(HEAD "[1600sub0]\nParameterValue=1\n[1600sub1]\nParameterValue=0x60400000\n",
                 "0x1600:01", "not a mapping entry");
    expect_error(HEAD "[1600sub0]\nParameterValue=2\n[1600sub1]\nParameterValue=0x60400010\n",
                 "0x1600:02", "missing");
    expect_error(HEAD "[1400sub1]\nDefaultValue=0x305\n[1600sub0]\nParameterValue=1\n"
                 "[1600sub1]\nParameterValue=0x60400010\n", "0x1400:01", "predefined 0x207");
    expect_error(HEAD "[2000]\nDataType=0x0005\nAccessType=rw\nParameterValue=300\n", "0x2000:00", "out of range");
    expect_error(HEAD "[2000]\nDataType=0x0009\nAccessType=rw\nParameterValue=abc\n", "0x2000:00", "DataType 0x0009");
    expect_error(HEAD "[2000]\nDataType=0x0007\nAccessType=rw\nParameterValue=12z\n", "0x2000:00", "not a number");
    expect_error(HEAD "[2000]\nDataType=seven\n", ":8:", "DataType 'seven'");
    expect_error(HEAD "[1600sub0]\nParameterValue=3\n[1600sub1]\nParameterValue=0x60400020\n"
                 "[1600sub2]\nParameterValue=0x607A0020\n[1600sub3]\nParameterValue=0x60FF0020\n", "0x1600", "64");
}
END_TEST

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s FOLDER (for the test's files)\n", argv[0]);
        return 2;
    }
    dir = argv[1];
    Suite *s = suite_create("canopen_eds");
    TCase *t = tcase_create("eds");
    tcase_add_test(t, example_drive_dcf);
    tcase_add_test(t, nodeid_values_and_signed_writes);
    tcase_add_test(t, bad_files_named);
    suite_add_tcase(s, t);
    SRunner *r = srunner_create(s);
    srunner_set_fork_status(r, CK_NOFORK);
    srunner_run_all(r, CK_ENV);
    int failed = srunner_ntests_failed(r);
    srunner_free(r);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}

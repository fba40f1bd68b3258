/*
 * The end of a Check test program's main(): run the suite (Check's
 * CK_VERBOSITY and CK_FORK from the environment) and give the exit status,
 * 0 when every test passed.
 */
#ifndef CHECK_RUN_H
#define CHECK_RUN_H

#include <check.h>

static inline int check_run(Suite *s)
{
    SRunner *r = srunner_create(s);
    srunner_run_all(r, CK_ENV);
    int failed = srunner_ntests_failed(r);
    srunner_free(r);
    return failed ? 1 : 0;
}

#endif

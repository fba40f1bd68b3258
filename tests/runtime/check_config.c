/* Config parsing: a full good file, and each kind of bad file, with the
** message naming file, line, section and key. */
#include <check.h>
#include <stdio.h>
#include <string.h>
#include "config.h"
#include "../common/check_run.h"

static plc_config c;
static char err[700];

static int load(const char *text)
{
    char e[600];
    ck_assert_int_eq(config_defaults(&c, e, sizeof e), 0);
    err[0] = 0;
    return config_load_string(&c, "plant.ini", text, err, sizeof err);
}

static void bad(const char *text, const char *want)
{
    ck_assert_msg(load(text) == -1, "accepted:\n%s", text);
    ck_assert_msg(strstr(err, want) != NULL, "message '%s' lacks '%s'", err, want);
    config_free(&c);
}

START_TEST(defaults)
{
    ck_assert_int_eq(load(""), 0);
    ck_assert_str_eq(c.mb_bind, "127.0.0.1");
    ck_assert_int_eq(c.mb_port, 1502);
    ck_assert_int_eq(c.mb_max_clients, 16);
    ck_assert_int_eq(c.mb_idle_timeout, 10);    /* issue: silent clients held slots 60 s */
    ck_assert_str_eq(c.backend, "sim");
    ck_assert_int_eq(c.priority, 80);
    ck_assert_int_eq(c.retain_period, 10);
    config_free(&c);
}
END_TEST

START_TEST(good_file)
{
    const char *t =
        "; comment\n"
        "[plc]\nlog_level = debug\nstatus_interval = 2\nstatus_vars = A.B, C.D\n"
        "[scan]\npriority = 0\ncpu = 1\nlock_memory = no\noverrun_log_interval = 5\n"
        "[io]\nbackend = none\n"
        "[sim.axis0]\nthis_key = is ignored while sim is not selected\n"
        "[modbus]\nenabled = yes\nbind = 0.0.0.0\nport = 5020\nmax_clients = 4\nidle_timeout = 0\n"
        "[modbus.symbols]\nCONFIG0.X = holding 9000 rw\nCONFIG0.Y = input 2000\n"
        "[retain]\nfile = /var/lib/plc/retain\nperiod = 0\n";
    ck_assert_msg(load(t) == 0, "%s", err);
    ck_assert_int_eq(c.status_interval, 2);
    ck_assert_int_eq(c.nstatus, 2);
    ck_assert_str_eq(c.status_vars[1], "C.D");
    ck_assert_int_eq(c.priority, 0);
    ck_assert_int_eq(c.cpu, 1);
    ck_assert_int_eq(c.lock_memory, 0);
    ck_assert_str_eq(c.backend, "none");
    ck_assert_str_eq(c.mb_bind, "0.0.0.0");
    ck_assert_int_eq(c.mb_port, 5020);
    ck_assert_int_eq(c.mb_max_clients, 4);
    ck_assert_int_eq(c.nsymbols, 2);
    ck_assert_int_eq(c.symbols[0].table, MB_HOLDING);
    ck_assert_int_eq(c.symbols[0].writable, 1);
    ck_assert_int_eq(c.symbols[0].line, 22);
    ck_assert_int_eq(c.symbols[1].table, MB_INPUT);
    ck_assert_str_eq(c.retain_file, "/var/lib/plc/retain");
    config_free(&c);
}
END_TEST

START_TEST(sim_good)
{
    const char *t = "[sim.axis0]\ndac = %QW4\ncounter = %ID7\nzero = %IX2.3\nmaxvel = 5e4\nresonance = 30\n"
                    "[sim.axis3]\ndac = %MW1\ncounter = %MD2\n";
    ck_assert_msg(load(t) == 0, "%s", err);
    config_free(&c);
}
END_TEST

START_TEST(syntax)
{
    bad("[plc]\nlog_level = info\nthis line has no equals sign\n", "plant.ini:3: syntax error");
    bad("[plc\nlog_level = info\n", "plant.ini:1: syntax error");
}
END_TEST

START_TEST(unknown)
{
    bad("[bogus]\nx = 1\n", "plant.ini:2: [bogus] x: unknown section");
    bad("[scan]\n\npriorty = 10\n", "plant.ini:3: [scan] priorty: unknown key");
    bad("[io]\nbackend = profibus\n", "plant.ini:2: [io] backend: unknown backend 'profibus' (known: none, sim");
    bad("[sim.axis9]\ndac = %QW0\n", "plant.ini:2: [sim.axis9] dac: unknown section");
    bad("[sim.axis0]\nspeed = 3\n", "[sim.axis0] speed: unknown key");
}
END_TEST

START_TEST(values)
{
    bad("[modbus]\nport = abc\n", "plant.ini:2: [modbus] port: 'abc' is not an integer in 1..65535");
    bad("[modbus]\nport = 70000\n", "[modbus] port: '70000' is not an integer");
    bad("[scan]\npriority = 100\n", "[scan] priority: '100'");
    bad("[scan]\nlock_memory = maybe\n", "[scan] lock_memory: 'maybe' is not yes or no");
    bad("[plc]\nlog_level = loud\n", "[plc] log_level: 'loud'");
    bad("[retain]\nperiod = -1\n", "[retain] period");
    bad("[modbus.symbols]\nA.B = register 100\n", "plant.ini:2: [modbus.symbols] A.B: table 'register'");
    bad("[modbus.symbols]\nA.B = holding\n", "expected TABLE ADDRESS [rw]");
    bad("[modbus.symbols]\nA.B = input 9000 rw\n", "read-only");
    bad("[modbus.symbols]\nA.B = holding 9000 ro\n", "the only flag is rw");
    bad("[sim.axis0]\ndac = %QW5000\n", "plant.ini:2: [sim.axis0] dac: '%QW5000' is not a located address inside the process image");
    bad("[sim.axis0]\ndac = %QD0\n", "must be a %..W address");
    bad("[sim.axis0]\ncounter = %QD0\n", "counter must be an input");
    bad("[sim.axis0]\nlag = -1\n", "[sim.axis0] lag: '-1' is not a number");
    bad("[sim.axis0]\nmaxvel = fast\n", "'fast' is not a number");
}
END_TEST

START_TEST(first_error_wins)
{
    bad("[modbus]\nport = x\n[scan]\nnope = 1\n", "plant.ini:2:");
    bad("[modbus]\nport = 1\nbad line\n[scan]\nnope = 1\n", "plant.ini:3: syntax");
}
END_TEST

START_TEST(missing_file)
{
    char e[600];
    ck_assert_int_eq(config_defaults(&c, e, sizeof e), 0);
    ck_assert_int_eq(config_load(&c, "/nonexistent/plant.ini", err, sizeof err), -1);
    ck_assert_msg(strstr(err, "/nonexistent/plant.ini: No such file") != NULL, "%s", err);
    config_free(&c);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("config");
    TCase *t = tcase_create("ini");
    tcase_add_test(t, defaults);
    tcase_add_test(t, good_file);
    tcase_add_test(t, sim_good);
    tcase_add_test(t, syntax);
    tcase_add_test(t, unknown);
    tcase_add_test(t, values);
    tcase_add_test(t, first_error_wins);
    tcase_add_test(t, missing_file);
    suite_add_tcase(s, t);
    return check_run(s);
}

/* Config parsing: a full good file, and each kind of bad file, with the
** message naming file, line, section and key; the checks against this host
** (bind address, CPU, retain folder); long lines; random damage. */
#include <arpa/inet.h>
#include <check.h>
#include <errno.h>
#include <netinet/in.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include <math.h>
#include "config.h"
#include "io_backend.h"
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
    ck_assert_int_eq(c.trace_samples, 16384);   /* the issue: at least 16384 per channel */
    ck_assert_int_eq(c.allow_force, 0);         /* forcing off unless enabled */
    config_free(&c);
    ck_assert_int_eq(load("[trace]\nsamples = 65536\n[debug]\nallow_force = yes\n"), 0);
    ck_assert_int_eq(c.trace_samples, 65536);
    ck_assert_int_eq(c.allow_force, 1);
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

/* The elastic modes, the disturbance and the new bindings of the sim
** backend (docs/config.md) */
START_TEST(sim_modes)
{
    const char *t = "[sim.axis0]\ndac = %QW0\ncounter = %ID0\nmotor_counter = %ID4\nload_acc = %MD7\n"
                    "mode1_hz = 53\nmode1_zeta = 0.05\nmode1_share = 3\nmode2_hz = 11\nmode2_zeta = 0.2\n"
                    "mode2_share = 1\ndist_amp = -2e5\ndist_hz = 0\ndist_start = 0.5\n";
    ck_assert_msg(load(t) == 0, "%s", err);
    config_free(&c);
    bad("[sim.axis0]\nmode1_zeta = 1\n", "plant.ini:2: [sim.axis0] mode1_zeta: '1' is not a number in 0..0.999");
    bad("[sim.axis0]\nmode2_hz = -3\n", "[sim.axis0] mode2_hz: '-3' is not a number");
    bad("[sim.axis0]\nmode1_share = 0\n", "[sim.axis0] mode1_share: '0' is not a number");
    bad("[sim.axis0]\nload_acc = %QD1\n", "load_acc must be an input");
    bad("[sim.axis0]\nmotor_counter = %IW1\n", "must be a %..D address");
    bad("[sim.axis0]\nresonance = 20\nmode2_hz = 53\n",
        "plant.ini:3: [sim.axis0] mode2_hz: resonance and mode1_hz/mode2_hz exclude each other");
    bad("[sim.axis0]\nmode1_hz = 53\nresonance = 20\n", "plant.ini:3: [sim.axis0] resonance: resonance and mode1_hz");
}
END_TEST

static void sim_set(const io_backend_ops *o, void *st, const char *k, const char *v)
{
    char e[200];
    ck_assert_msg(o->config(st, "sim.axis0", k, v, e, sizeof e) == 0, "%s = %s: %s", k, v, e);
}

/* The backend runs the modes: a force step on the load (motor still) shows
** as d'' = F e^(-s t)(cos wd t - s/wd sin wd t) on load_acc. */
START_TEST(sim_modes_run)
{
    const io_backend_ops *o = io_backend_find("sim");
    static plc_image img;
    char e[300];
    void *st = o->create();
    sim_set(o, st, "dac", "%QW0"); sim_set(o, st, "counter", "%ID0");
    sim_set(o, st, "dac", "%QW0"); sim_set(o, st, "counter", "%ID0");
    sim_set(o, st, "motor_counter", "%ID4"); sim_set(o, st, "load_acc", "%ID5");
    sim_set(o, st, "mode1_hz", "53"); sim_set(o, st, "mode1_zeta", "0.05");
    sim_set(o, st, "dist_amp", "200000"); sim_set(o, st, "dist_start", "0");
    ck_assert_msg(o->open(st, &img, 1000000, e, sizeof e) == 0, "%s", e);
    double w = 2 * M_PI * 53, sg = 0.05 * w, wd = w * sqrt(1 - 0.05 * 0.05);
    for (int i = 0; i <= 100; i++) {
        ck_assert_int_eq(o->read_inputs(st, &img, (uint64_t)i * 1000000), 0);
        o->write_outputs(st, &img);
        double t = i * 1e-3, a = 2e5 * exp(-sg * t) * (cos(wd * t) - sg / wd * sin(wd * t));
        if (i == 0) a = 0;    /* the first cycle is the start: no time has passed */
        ck_assert_msg(abs(img_get32(img.id, 5) - (int32_t)lround(a)) <= 1, "load_acc %d at %g s, expected %.0f",
                      img_get32(img.id, 5), t, a);
        ck_assert_int_eq(img_get32(img.id, 4), 0);
    }
    ck_assert_int_eq(img_get32(img.id, 0), (int32_t)floor(2e5 / (w * w) * (1 - exp(-sg * 0.1) *
                     (cos(wd * 0.1) + sg / wd * sin(wd * 0.1)))));
    o->close(st);
}
END_TEST

static int sec_set(const io_backend_ops *o, void *st, const char *sec, const char *k, const char *v,
                   char *e, size_t n)
{
    return o->config(st, sec, k, v, e, n);
}

#define SET(sec, k, v) ck_assert_msg(sec_set(o, st, sec, k, v, e, sizeof e) == 0, "%s %s = %s: %s", sec, k, v, e)

/* [sim.master] and [sim.markerN] in the backend: the master's counter is
** speed x t (floor), a marker on it pulses at first + k pitch with the count
** latched there (noise 0), one on an axis fed by the master's follower. */
START_TEST(sim_master_markers)
{
    const io_backend_ops *o = io_backend_find("sim");
    static plc_image img;
    char e[300];
    void *st = o->create();
    SET("sim.axis0", "dac", "%QW0"); SET("sim.axis0", "counter", "%ID0");
    SET("sim.master", "counter", "%ID2"); SET("sim.master", "speed", "4000");
    SET("sim.marker0", "first", "1000"); SET("sim.marker0", "pitch", "1500");
    SET("sim.marker0", "input", "%IX1.0"); SET("sim.marker0", "latch", "%ID3"); SET("sim.marker0", "count", "%IW8");
    ck_assert_msg(o->open(st, &img, 0, e, sizeof e) == 0, "%s", e);
    int pulses = 0;
    for (int i = 0; i <= 1000; i++) {
        ck_assert_int_eq(o->read_inputs(st, &img, (uint64_t)i * 1000000), 0);
        o->write_outputs(st, &img);
        int32_t x = img_get32(img.id, 2);
        ck_assert_msg(abs(x - 4 * i) <= 1, "master %d at %d ms, expected %d", x, i, 4 * i);
        if (img.ix[8]) {      /* %IX1.0: one byte per bit */
            pulses++;
            ck_assert_int_eq(img_get32(img.id, 3), 1000 + 1500 * (pulses - 1));
            ck_assert_msg(x >= img_get32(img.id, 3) && x - 4 <= img_get32(img.id, 3), "pulse late: %d", x);
        }
    }
    ck_assert_int_eq(pulses, 3);      /* 1000, 2500 and 4000: the master reaches 4000 at 1 s */
    ck_assert_int_eq(img_get16(img.iw, 8), 3);
    o->close(st);

    /* refused at open: a master without counter, a marker on an absent master, too much noise */
    st = o->create();
    SET("sim.master", "speed", "1");
    ck_assert_int_ne(o->open(st, &img, 0, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "[sim.master]: counter must be set"), "%s", e);
    o->close(st);
    st = o->create();
    SET("sim.marker1", "pitch", "100");
    ck_assert_int_ne(o->open(st, &img, 0, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "[sim.marker1]: on = master, and no [sim.master]"), "%s", e);
    o->close(st);
    st = o->create();
    SET("sim.marker0", "on", "axis0"); SET("sim.marker0", "pitch", "100"); SET("sim.marker0", "noise", "50");
    ck_assert_int_ne(o->open(st, &img, 0, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "noise must be below half the pitch"), "%s", e);
    o->close(st);
    bad("[sim.marker4]\npitch = 1\n", "[sim.marker4] pitch: unknown section");
    bad("[sim.marker0]\non = axis8\n", "'axis8': master or axis0 .. axis7");
    bad("[sim.master]\nfollow = master\n", "the master cannot follow itself");
    bad("[sim.master]\ncounter = %QD1\n", "must be an input");
    bad("[sim.master]\nspeed = fast\n", "'fast' is not a number");
}
END_TEST

/* [sim] clock: plc moves the plant on by the PLC time between two scans
** (missed cycles too, as a real axis), cycles by one task interval per
** scan: 5 V for 100 scans whose PLC time jumps by 3 ms once (a late scan)
** gives 102 ms and 100 ms of motion at 5000 counts/s (lag 0). */
START_TEST(sim_clock)
{
    const io_backend_ops *o = io_backend_find("sim");
    static plc_image img;
    char e[300];
    for (int cyc = 0; cyc <= 1; cyc++) {
        void *st = o->create();
        SET("sim.axis0", "dac", "%QW0"); SET("sim.axis0", "counter", "%ID0"); SET("sim.axis0", "lag", "0");
        SET("sim.axis0", "maxvel", "10000");
        if (cyc) SET("sim", "clock", "cycles");
        ck_assert_msg(o->open(st, &img, 1000000, e, sizeof e) == 0, "%s", e);
        img_set16(img.qw, 0, 16384);
        uint64_t t = 0;
        for (int i = 0; i <= 100; i++) {
            t += i == 50 ? 3000000 : i ? 1000000 : 0;
            ck_assert_int_eq(o->read_inputs(st, &img, t), 0);
            o->write_outputs(st, &img);
        }
        double x = 10000 * (16384 * 10.0 / 32767) / 10 * (cyc ? 0.100 : 0.102);
        ck_assert_msg(fabs(img_get32(img.id, 0) - x) <= 2, "clock %s: %d counts, expected about %.0f",
                      cyc ? "cycles" : "plc", img_get32(img.id, 0), x);
        o->close(st);
    }
    bad("[sim]\nclock = wall\n", "'wall': plc (the plant moves on by the PLC time");
    bad("[sim]\nclk = plc\n", "unknown key (clock;");
}
END_TEST

/* follow: an encoder on an axis: start + ratio x the axis's position */
START_TEST(sim_master_follow)
{
    const io_backend_ops *o = io_backend_find("sim");
    static plc_image img;
    char e[300];
    void *st = o->create();
    SET("sim.axis1", "dac", "%QW1"); SET("sim.axis1", "counter", "%ID1"); SET("sim.axis1", "lag", "0");
    SET("sim.axis1", "maxvel", "10000");
    SET("sim.master", "counter", "%ID2"); SET("sim.master", "follow", "axis1");
    SET("sim.master", "ratio", "2"); SET("sim.master", "start", "100");
    ck_assert_msg(o->open(st, &img, 0, e, sizeof e) == 0, "%s", e);
    img_set16(img.qw, 1, 16384);     /* 5 V: 5000 counts/s */
    for (int i = 0; i <= 100; i++) {
        ck_assert_int_eq(o->read_inputs(st, &img, (uint64_t)i * 1000000), 0);
        o->write_outputs(st, &img);
    }
    double ax = 10000 * (16384 * 10.0 / 32767) / 10 * 0.099;   /* 99 ms at speed: the first step starts it */
    ck_assert_msg(fabs(img_get32(img.id, 1) - ax) <= 6, "axis %d, expected about %.0f", img_get32(img.id, 1), ax);
    ck_assert_msg(abs(img_get32(img.id, 2) - (100 + 2 * img_get32(img.id, 1))) <= 2, "master %d, axis %d",
                  img_get32(img.id, 2), img_get32(img.id, 1));
    o->close(st);
}
END_TEST

/* Several backends at once (docs/config.md [io]): each reads its own
** sections; a bad list is refused naming the culprit. */
START_TEST(several_backends)
{
    const char *t = "[io]\nbackend = none ,sim\n[sim.axis0]\ndac = %QW4\ncounter = %ID7\n";
    ck_assert_msg(load(t) == 0, "%s", err);
    ck_assert_str_eq(c.backend, "none, sim");
    ck_assert_int_eq(io_multi_count(c.io_state), 2);
    ck_assert_ptr_nonnull(io_multi_state(c.io_state, io_backend_find("sim")));
    ck_assert_ptr_null(io_multi_state(c.io_state, io_backend_find("canopen")));
    config_free(&c);
    /* a section of the listed sim read by sim: its bad key refused */
    ck_assert_int_ne(load("[io]\nbackend = none, sim\n[sim.axis0]\nnokey = 1\n"), 0);
    ck_assert_msg(strstr(err, "[sim.axis0] nokey"), "%s", err);
    config_free(&c);
    static const struct { const char *v, *says; } bad[] = {
        { "sim, sim", "backend sim listed twice" },
        { "sim,", "may not end with a comma" },
        { "sim,,none", "an empty name" },
        { "sim, foo", "unknown backend 'foo'" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char txt[100];
        snprintf(txt, sizeof txt, "[io]\nbackend = %s\n", bad[i].v);
        ck_assert_int_ne(load(txt), 0);
        ck_assert_msg(strstr(err, bad[i].says) && strstr(err, "[io] backend"), "%s: %s", bad[i].v, err);
        config_free(&c);
    }
}
END_TEST

/* [modbus_io.NAME] (docs/remote-io.md): good keys taken, each bad one
** refused naming file, line, section and key, and saying what is wanted */
START_TEST(modbus_io_keys)
{
    const char *good = "[io]\nbackend = modbus_io\n[modbus_io.rack]\nhost = 10.0.0.2\nport = 1502\nunit = 3\n"
                       "period_ms = 10\nword_order = low_first\nok = %IX10.0\n"
                       "read = input 0 4 %IW0 safe=-5\nread = holding 10 2 %ID0\nread = discrete 0 16 %IX0.0\n"
                       "write = coil 0 8 %QX0.0\nwrite = holding 100 2 %QD1\n"
                       "[modbus_io.rtu]\ndevice = /dev/ttyUSB0\nbaud = 9600\nparity = odd\nstop_bits = 2\nslave = 7\n"
                       "read = input 0 1 %IW10\n";
    ck_assert_msg(load(good) == 0, "%s", err);
    config_free(&c);
    static const struct { const char *line, *says; } cases[] = {
        { "read = input 0 126 %IW0", "count '126' is not in 1..125" },
        { "read = input 0 4 %QW0", "a read block goes to an input" },
        { "read = coil 0 4 %IW0", "coils are bits: give a %IX location" },
        { "read = holding 0 3 %ID0", "give an even count" },
        { "read = holding 0 4 %IX0.0", "registers go to %IW (16-bit) or %ID" },
        { "write = input 0 4 %QW0", "cannot be written" },
        { "write = coil 0 4 %IX0.0", "a write block goes to an output" },
        { "read = input 0 4 %IW0 safe=70000", "a decimal value in -32768..65535" },
        { "read = input 0 4 %IW0 hold", "the only option is safe=VALUE" },
        { "read = register 0 4 %IW0", "table 'register' is not coil, discrete, input or holding" },
        { "read = input 65535 2 %IW0", "pass address 65535" },
        { "read = input 0 4 %IW1022", "pass the end of the image" },
        { "read = input 0", "expected TABLE START COUNT LOCATION" },
        { "parity = mark", "'mark' is not none, even or odd" },
        { "word_order = big", "not high_first or low_first" },
        { "ok = %QX0.0", "is not an input bit" },
        { "slave = 0", "not a decimal number in 1..247" },
        { "colour = red", "unknown key" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char txt[200];
        snprintf(txt, sizeof txt, "[io]\nbackend = modbus_io\n[modbus_io.rack]\n%s\n", cases[i].line);
        ck_assert_int_ne(load(txt), 0);
        ck_assert_msg(strstr(err, cases[i].says) && strstr(err, "plant.ini:4: [modbus_io.rack]"), "%s: %s",
                      cases[i].line, err);
        config_free(&c);
    }
    /* a section without a name */
    ck_assert_int_ne(load("[io]\nbackend = modbus_io\n[modbus_io]\nhost = x\n"), 0);
    ck_assert_msg(strstr(err, "[modbus_io.NAME]"), "%s", err);
    config_free(&c);
}
END_TEST

/* [modbus_rtu] (docs/config.md): the map on a serial line */
START_TEST(modbus_rtu_keys)
{
    ck_assert_msg(load("[modbus_rtu]\ndevice = /dev/ttyS1\nbaud = 9600\nparity = none\nstop_bits = 2\nslave = 9\n") == 0,
                  "%s", err);
    ck_assert_str_eq(c.rtu_device, "/dev/ttyS1");
    ck_assert_int_eq(c.rtu_baud, 9600);
    ck_assert_int_eq(c.rtu_parity, 'N');
    ck_assert_int_eq(c.rtu_stop_bits, 2);
    ck_assert_int_eq(c.rtu_slave, 9);
    config_free(&c);
    ck_assert_int_eq(load(""), 0);
    ck_assert_str_eq(c.rtu_device, "");                 /* off by default */
    ck_assert_int_eq(c.rtu_parity, 'E');                /* Modbus's default */
    config_free(&c);
    bad("[modbus_rtu]\nparity = mark\n", "plant.ini:2: [modbus_rtu] parity: 'mark' is not none, even or odd");
    bad("[modbus_rtu]\nslave = 0\n", "[modbus_rtu] slave");
    bad("[modbus_rtu]\nbaud = 9600\nbaud = 19200\n", "given twice (first on line 2)");
    bad("[modbus_rtu]\nspeed = 9600\n", "[modbus_rtu] speed: unknown key");
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
    bad("[modbus]\nport = abc\n", "plant.ini:2: [modbus] port: 'abc' is not a decimal integer in 1..65535");
    bad("[modbus]\nport = 70000\n", "[modbus] port: '70000' is not a decimal integer in 1..65535");
    bad("[scan]\npriority = 100\n", "[scan] priority: '100'");
    bad("[scan]\nlock_memory = maybe\n", "[scan] lock_memory: 'maybe' is not yes or no");
    bad("[plc]\nlog_level = loud\n", "[plc] log_level: 'loud'");
    bad("[retain]\nperiod = -1\n", "[retain] period");
    bad("[trace]\nsamples = 1000\n", "plant.ini:2: [trace] samples: '1000' is not a decimal integer in 16384..1048576");
    bad("[debug]\nallow_force = maybe\n", "plant.ini:2: [debug] allow_force: 'maybe' is not yes or no");
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

/* Ports and every other integer are decimal: a leading zero is not octal
** (017353 octal would be 7915), 0x is not hexadecimal. */
START_TEST(decimal)
{
    ck_assert_msg(load("[modbus]\nport = 017353\n[scan]\npriority = 010\ncpu = -01\n") == 0, "%s", err);
    ck_assert_int_eq(c.mb_port, 17353);
    ck_assert_int_eq(c.priority, 10);
    ck_assert_int_eq(c.cpu, -1);
    config_free(&c);
    bad("[modbus]\nport = 0x10\n", "plant.ini:2: [modbus] port: '0x10' is not a decimal integer");
    bad("[modbus]\nport = 0\n", "plant.ini:2: [modbus] port: '0' is not a decimal integer in 1..65535");
    bad("[modbus]\nport = 65536\n", "[modbus] port: '65536'");
    bad("[modbus]\nport = 99999999999999999999\n", "[modbus] port: '99999999999999999999'");
    bad("[modbus]\nport = 15 02\n", "[modbus] port: '15 02'");
    bad("[modbus.symbols]\nA.B = holding 0x10\n", "plant.ini:2: [modbus.symbols] A.B: address '0x10'");
    ck_assert_msg(load("[modbus.symbols]\nA.B = holding 010\n") == 0, "%s", err);
    ck_assert_int_eq(c.symbols[0].addr, 10);
    config_free(&c);
}
END_TEST

/* A host name is resolved once, to the IPv4 address the server listens on
** ("localhost" is 127.0.0.1 in every /etc/hosts); what the IPv4-only
** server cannot listen on is refused at its line. */
START_TEST(bind_names)
{
    ck_assert_msg(load("[modbus]\nbind = localhost\n") == 0, "%s", err);
    ck_assert_str_eq(c.mb_bind, "127.0.0.1");
    ck_assert_str_eq(c.mb_bind_name, "localhost");
    config_free(&c);
    ck_assert_msg(load("[modbus]\nbind = 0.0.0.0\n") == 0, "%s", err);
    ck_assert_str_eq(c.mb_bind, "0.0.0.0");
    ck_assert_str_eq(c.mb_bind_name, "");
    config_free(&c);
    bad("[modbus]\nport = 1502\nbind = ::1\n", "plant.ini:3: [modbus] bind: '::1' is an IPv6 address");
    bad("[modbus]\nbind = fe80::1\n", "plant.ini:2: [modbus] bind: 'fe80::1' is an IPv6 address");
    bad("[modbus]\nbind = 127.0.0.1:502\n", "plant.ini:2: [modbus] bind: '127.0.0.1:502' is not an address");
    bad("[modbus]\nbind = 255.255.255.255\n", "plant.ini:2: [modbus] bind: '255.255.255.255' is a broadcast address");
    bad("[modbus]\nbind = 224.0.0.1\n", "[modbus] bind: '224.0.0.1' is a multicast address");
    bad("[modbus]\nbind = 010.0.0.1\n", "[modbus] bind: '010.0.0.1' is not an IPv4 address");
    bad("[modbus]\nbind = 127.1\n", "[modbus] bind: '127.1' is not an IPv4 address");
    bad("[modbus]\nbind = 0.1.2.3\n", "[modbus] bind: '0.1.2.3' is not an address of a host");
    bad("[modbus]\nbind =\n", "plant.ini:2: [modbus] bind: empty");
}
END_TEST

/* An address of the documentation ranges (RFC 5737) that this host cannot
** bind, found with a plain bind(); NULL if it has them all. */
static const char *foreign_address(void)
{
    static const char *cand[] = { "192.0.2.1", "198.51.100.1", "203.0.113.1", "192.0.2.254" };
    for (size_t i = 0; i < sizeof cand / sizeof cand[0]; i++) {
        int fd = socket(AF_INET, SOCK_STREAM, 0);
        struct sockaddr_in sa = { .sin_family = AF_INET };
        inet_pton(AF_INET, cand[i], &sa.sin_addr);
        int r = bind(fd, (struct sockaddr *)&sa, sizeof sa), e = errno;
        close(fd);
        if (r && e == EADDRNOTAVAIL) return cand[i];
    }
    return NULL;
}

START_TEST(bind_host)
{
    const char *a = foreign_address();
    ck_assert_msg(a != NULL, "every candidate address is on this host");
    char t[200], want[200];
    snprintf(t, sizeof t, "[modbus]\nport = 1502\nbind = %s\n", a);
    ck_assert_msg(load(t) == 0, "%s", err);           /* a good address, of another host */
    ck_assert_int_eq(config_check_host(&c, 0, err, sizeof err), -1);
    snprintf(want, sizeof want, "plant.ini:3: [modbus] bind: %s is not an address of this host", a);
    ck_assert_msg(strstr(err, want) != NULL, "message '%s' lacks '%s'", err, want);
    config_free(&c);
    /* not served: not checked against this host */
    snprintf(t, sizeof t, "[modbus]\nenabled = no\nbind = %s\n", a);
    ck_assert_msg(load(t) == 0, "%s", err);
    ck_assert_msg(config_check_host(&c, 0, err, sizeof err) == 0, "%s", err);
    config_free(&c);
    ck_assert_msg(load("[modbus]\nbind = localhost\n[retain]\nfile =\n") == 0, "%s", err);
    ck_assert_msg(config_check_host(&c, 1, err, sizeof err) == 0, "%s", err);
    config_free(&c);
}
END_TEST

START_TEST(cpu_host)
{
    cpu_set_t set;
    ck_assert_int_eq(sched_getaffinity(0, sizeof set, &set), 0);
    int missing = -1;
    for (int i = 0; i < 1024 && missing < 0; i++) if (!CPU_ISSET(i, &set)) missing = i;
    char t[100], want[100];
    snprintf(t, sizeof t, "[retain]\nfile =\n[scan]\ncpu = %d\n", missing);
    ck_assert_msg(load(t) == 0, "%s", err);
    ck_assert_int_eq(config_check_host(&c, 0, err, sizeof err), -1);
    snprintf(want, sizeof want, "plant.ini:4: [scan] cpu: CPU %d is not one this process may run on", missing);
    ck_assert_msg(strstr(err, want) != NULL, "message '%s' lacks '%s'", err, want);
    config_free(&c);
}
END_TEST

/* The retain file is written beside itself (temporary file, rename): its
** folder must exist and be writable. */
START_TEST(retain_host)
{
    ck_assert_msg(load("[plc]\n[retain]\nfile = /nonexistent-plc/var/plc.retain\n") == 0, "%s", err);
    ck_assert_int_eq(config_check_host(&c, 0, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "plant.ini:3: [retain] file: folder /nonexistent-plc/var: No such file") != NULL, "%s", err);
    config_free(&c);
    char d[200];
    snprintf(d, sizeof d, "[retain]\nfile = %s\n", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    ck_assert_msg(load(d) == 0, "%s", err);
    ck_assert_int_eq(config_check_host(&c, 0, err, sizeof err), -1);
    ck_assert_msg(strstr(err, "plant.ini:2: [retain] file: ") && strstr(err, "is not a regular file"), "%s", err);
    config_free(&c);
    /* the default file, in the working folder, when the program retains */
    ck_assert_msg(load("") == 0, "%s", err);
    ck_assert_msg(config_check_host(&c, 1, err, sizeof err) == 0, "%s", err);
    config_free(&c);
}
END_TEST

START_TEST(folder)
{
    char e[600];
    const char *dir = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    ck_assert_int_eq(config_defaults(&c, e, sizeof e), 0);
    ck_assert_int_eq(config_load(&c, dir, err, sizeof err), -1);
    char want[300];
    snprintf(want, sizeof want, "%s: is a folder, not a configuration file", dir);
    ck_assert_msg(strstr(err, want) != NULL, "message '%s' lacks '%s'", err, want);
    config_free(&c);
}
END_TEST

/* libinih's own buffer holds 199 characters: longer lines up to
** CFG_MAX_LINE are read whole and keep their line numbers. */
START_TEST(long_lines)
{
    char t[6000], vars[3000] = "";
    /* a 207-character status_vars line: 7 paths of 22 characters, one of 25 */
    for (int i = 0; i < 8; i++)
        snprintf(vars + strlen(vars), sizeof vars - strlen(vars), "%sCONFIG0.RES0.INST0.V%02d%s",
                 i ? ", " : "", i, i == 7 ? "XYZ" : "");
    snprintf(t, sizeof t, "status_vars = %s", vars);
    ck_assert_int_eq(strlen(t), 207);
    snprintf(t, sizeof t, "[plc]\nstatus_vars = %s\n[scan]\npriority = 5\n", vars);
    ck_assert_msg(load(t) == 0, "%s", err);
    ck_assert_int_eq(c.nstatus, 8);
    ck_assert_str_eq(c.status_vars[0], "CONFIG0.RES0.INST0.V00");
    ck_assert_str_eq(c.status_vars[7], "CONFIG0.RES0.INST0.V07XYZ");
    ck_assert_int_eq(c.priority, 5);
    ck_assert_int_eq(config_line(&c, "plc", "status_vars"), 2);
    ck_assert_int_eq(config_line(&c, "scan", "priority"), 4);
    config_free(&c);
    /* an error after long lines is at its own line */
    snprintf(t, sizeof t, "[plc]\nstatus_vars = %s\n; %0300d\n\n[scan]\npriorty = 5\n", vars, 0);
    bad(t, "plant.ini:6: [scan] priorty: unknown key");
    /* a long line's inline comment, indent and CRLF, as on a short line */
    snprintf(t, sizeof t, "[plc]\r\n  status_vars = A.B ; %0300d \r\n", 0);
    ck_assert_msg(load(t) == 0, "%s", err);
    ck_assert_int_eq(c.nstatus, 1);
    ck_assert_str_eq(c.status_vars[0], "A.B");
    config_free(&c);
    /* a long key: a symbol path of 159 characters, and its line */
    char path[160];
    memset(path, 'P', 159);
    path[159] = 0;
    memcpy(path, "CONFIG0.", 8);
    snprintf(t, sizeof t, "[modbus.symbols]\nA.B = holding 1\n%s = holding 9000 rw ; wide\n", path);
    ck_assert_msg(load(t) == 0, "%s", err);
    ck_assert_int_eq(c.nsymbols, 2);
    ck_assert_str_eq(c.symbols[1].path, path);
    ck_assert_int_eq(c.symbols[1].addr, 9000);
    ck_assert_int_eq(c.symbols[1].writable, 1);
    ck_assert_int_eq(c.symbols[1].line, 3);
    config_free(&c);
    /* long bad lines: a value, a section, no '=' */
    snprintf(t, sizeof t, "[modbus]\nport = %0250dx\n", 0);
    bad(t, "plant.ini:2: [modbus] port: '0000");
    snprintf(t, sizeof t, "[scan]\n[x%0250d]\nkey = 1\n", 0);
    bad(t, "plant.ini:3: [x0000");
    snprintf(t, sizeof t, "[scan]\npriority = 1\n%0250d\n", 0);
    bad(t, "plant.ini:3: syntax error");
    /* beyond the maximum: refused at its own line */
    char *big = malloc(CFG_MAX_LINE + 200);
    ck_assert_ptr_nonnull(big);
    int n = snprintf(big, CFG_MAX_LINE + 200, "[plc]\nlog_level = info\nstatus_vars = ");
    memset(big + n, 'A', CFG_MAX_LINE + 1 - 14);
    strcpy(big + n + CFG_MAX_LINE + 1 - 14, "\n[scan]\npriority = 1\n");
    char want[120];
    snprintf(want, sizeof want, "plant.ini:3: [plc] status_vars: line of %d characters; at most %d", CFG_MAX_LINE + 1, CFG_MAX_LINE);
    bad(big, want);
    free(big);
}
END_TEST

START_TEST(whole)
{
    bad("[modbus]\nport = 1502\n\nport = 1503\n", "plant.ini:4: [modbus] port: given twice (first on line 2)");
    bad("[plc]\nlog_level = in\001fo\n", "plant.ini:2: [plc] log_level: control character 0x01 in column 15");
    bad("[plc]\nstatus_vars = A, B, C, D, E, F, G, H, I\n", "plant.ini:2: [plc] status_vars: more than 8 variables");
    /* the first error in the file wins, whatever finds it */
    bad("[modbus]\nport = x\n[io]\nbackend = profibus\n", "plant.ini:2: [modbus] port");
    bad("[io]\nbackend = profibus\n[modbus]\nport = x\n", "plant.ini:2: [io] backend");
    bad("[modbus]\nport = x\nbad line\n", "plant.ini:2: [modbus] port");
    /* an indent is not a continuation of the value above (libinih's
    ** multi-line values): a line like any other */
    ck_assert_msg(load("[modbus]\n  port = 1600\n\tbind = localhost\n") == 0, "%s", err);
    ck_assert_int_eq(c.mb_port, 1600);
    ck_assert_str_eq(c.mb_bind, "127.0.0.1");
    config_free(&c);
    bad("[plc]\nstatus_vars = A.B,\n    C.D\n", "plant.ini:3: syntax error");
    /* a byte order mark is not part of the first line */
    ck_assert_msg(load("\xEF\xBB\xBF[modbus]\nport = 1600\n") == 0, "%s", err);
    ck_assert_int_eq(c.mb_port, 1600);
    config_free(&c);
}
END_TEST

/* Later checks (program, host) word their messages the same way; a key
** left at its default is named as such. */
START_TEST(messages)
{
    ck_assert_msg(load("[scan]\n\npriority = 5\n") == 0, "%s", err);
    char m[300];
    config_msg(&c, "scan", "priority", m, sizeof m, "refused by %s", "the kernel");
    ck_assert_str_eq(m, "plant.ini:3: [scan] priority: refused by the kernel");
    config_msg(&c, "retain", "file", m, sizeof m, "folder %s: gone", ".");
    ck_assert_str_eq(m, "plant.ini: [retain] file (default): folder .: gone");
    ck_assert_int_eq(config_line(&c, "scan", "priority"), 3);
    ck_assert_int_eq(config_line(&c, "scan", "cpu"), 0);
    ck_assert_int_eq(config_line(&c, "nosuch", "key"), 0);
    config_free(&c);
}
END_TEST

/* Bad files never crash (this suite also runs under ASan/UBSan): a good
** file with bytes changed, inserted or dropped at random. */
START_TEST(robust)
{
    static const char good[] =
        "[plc]\nlog_level = debug\nstatus_interval = 2\n"
        "[scan]\npriority = 0\ncpu = 1\nlock_memory = no\n"
        "[io]\nbackend = sim\n[sim.axis0]\ndac = %QW4\nmaxvel = 5e4\n"
        "[modbus.symbols]\nCONFIG0.X = holding 9000 rw\n[retain]\nperiod = 0\n"
        "[plc]\nstatus_vars = CONFIG0.RES0.LONG.NAME.OF.A.VARIABLE.ONE, CONFIG0.RES0.LONG.NAME.OF.A.VARIABLE.TWO, "
        "CONFIG0.RES0.LONG.NAME.OF.A.VARIABLE.THREE, CONFIG0.RES0.LONG.NAME.OF.A.VARIABLE.FOUR ; and a comment\n"
        "  [modbus.symbols] ; a long section line, indented ...........................................\n"
        "CONFIG0.RES0.LONG.NAME.OF.A.VARIABLE.ONE.AT.THE.HOLDING.REGISTERS.OF.THE.MAP.AND.MORE.TEXT = holding 300\n";
    static const char bytes[] = "[]=;:# \t\n\r,.%0123456789aAzZ\001\377";
    char t[1200];
    unsigned seed = 12345;
    int accepted = 0, refused = 0;
    ck_assert_msg(load(good) == 0, "%s", err);
    ck_assert_int_eq(c.nstatus, 4);
    ck_assert_int_eq(c.nsymbols, 2);
    config_free(&c);
    for (int k = 0; k < 3000; k++) {
        strcpy(t, good);
        size_t len = strlen(t);
        for (int m = 0; m < 3; m++) {
            size_t at = (size_t)rand_r(&seed) % len;
            char b = bytes[(size_t)rand_r(&seed) % (sizeof bytes - 1)];
            switch (rand_r(&seed) % 3) {
            case 0: t[at] = b; break;
            case 1: if (len < sizeof t - 2) { memmove(t + at + 1, t + at, len - at + 1); t[at] = b; len++; } break;
            default: memmove(t + at, t + at + 1, len - at); len--; break;
            }
        }
        if (load(t) == 0) accepted++;
        else {
            refused++;
            ck_assert_msg(!strncmp(err, "plant.ini:", 10), "message '%s'", err);
        }
        config_free(&c);
    }
    ck_assert_int_gt(refused, 1000);
    ck_assert_int_gt(accepted, 10);
}
END_TEST

/* What a careless hand writes into the backends' sections: a key given
** twice (the second silently won), nan (passed every range check and made
** the plant nan), two axes writing one counter (each loop followed the
** other's encoder), a node id with a leading zero (read as octal: id = 010
** drove node 8). */
START_TEST(careless_backend)
{
    bad("[sim.axis0]\ndac = %QW1\ncounter = %ID1\ndac = %QW2\n",
        "plant.ini:4: [sim.axis0] dac: given twice (first on line 2)");
    bad("[sim.axis0]\ndac = %QW1\n[sim.axis1]\ndac = %QW2\n[sim.axis0]\ndac = %QW3\n",
        "plant.ini:6: [sim.axis0] dac: given twice (first on line 2)");
    bad("[sim.axis0]\nmaxvel = nan\n", "plant.ini:2: [sim.axis0] maxvel: 'nan' is not a number in 0..1e+09");
    bad("[sim.axis0]\nlag = NAN\n", "[sim.axis0] lag: 'NAN' is not a number");
    bad("[sim.axis0]\noffset = -inf\n", "[sim.axis0] offset: '-inf' is not a number");
    bad("[sim.master]\nspeed = nan\n", "[sim.master] speed: 'nan' is not a number");
    bad("[sim.marker0]\nnoise = nan\n", "[sim.marker0] noise: 'nan' is not a number");

    const io_backend_ops *o = io_backend_find("sim");
    static plc_image img;
    char e[300];
    void *st = o->create();
    SET("sim.axis0", "dac", "%QW0"); SET("sim.axis0", "counter", "%ID0");
    SET("sim.axis1", "dac", "%QW0"); SET("sim.axis1", "counter", "%ID0");
    ck_assert_int_ne(o->open(st, &img, 0, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "[sim.axis0] counter and [sim.axis1] counter write the same input"), "%s", e);
    o->close(st);
    st = o->create();               /* a %MD counter over an %MD zero latch of the master */
    SET("sim.axis0", "dac", "%QW0"); SET("sim.axis0", "counter", "%MD4");
    SET("sim.master", "counter", "%MD4");
    ck_assert_int_ne(o->open(st, &img, 0, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "[sim.axis0] counter and [sim.master] counter write the same input"), "%s", e);
    o->close(st);
    st = o->create();               /* one DAC for two drives, each its own encoder: fine */
    SET("sim.axis0", "dac", "%QW0"); SET("sim.axis0", "counter", "%ID0");
    SET("sim.axis1", "dac", "%QW0"); SET("sim.axis1", "counter", "%ID1");
    ck_assert_msg(o->open(st, &img, 0, e, sizeof e) == 0, "%s", e);
    o->close(st);

    /* CANopen: checked at open before the bus is opened */
    o = io_backend_find("canopen");
    ck_assert_ptr_nonnull(o);
    st = o->create();
    ck_assert_msg(o->config(st, "canopen.a", "id", "010", e, sizeof e) == 0, "%s", e);
    ck_assert_msg(o->config(st, "canopen.b", "id", "10", e, sizeof e) == 0, "%s", e);
    ck_assert_int_ne(o->open(st, &img, 1000000, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "[canopen.a] and [canopen.b] both have id 10"), "%s", e);
    o->close(st);
    st = o->create();
    ck_assert_msg(o->config(st, "canopen.a", "id", "0x0A", e, sizeof e) == 0, "%s", e);
    ck_assert_msg(o->config(st, "canopen.b", "id", "10", e, sizeof e) == 0, "%s", e);
    ck_assert_int_ne(o->open(st, &img, 1000000, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "both have id 10"), "%s", e);
    o->close(st);
    st = o->create();               /* 09: refused as a bad octal number before */
    ck_assert_msg(o->config(st, "canopen.a", "id", "09", e, sizeof e) == 0, "%s", e);
    ck_assert_msg(o->config(st, "canopen.b", "id", "9", e, sizeof e) == 0, "%s", e);
    ck_assert_int_ne(o->open(st, &img, 1000000, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "both have id 9"), "%s", e);
    o->close(st);
    /* two nodes bound to one input: refused before the bus is opened; one
    ** output driving two objects is fine */
    st = o->create();
#define CO(sec, k, v) ck_assert_msg(o->config(st, sec, k, v, e, sizeof e) == 0, "%s %s = %s: %s", sec, k, v, e)
    CO("canopen.left", "id", "1"); CO("canopen.right", "id", "2");
    CO("canopen.left", "bind", "0x6000:01 %IB4"); CO("canopen.right", "bind", "0x6000:01 %IB4");
    ck_assert_int_ne(o->open(st, &img, 1000000, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "[canopen.left] bind 0x6000:01 %IB4 and [canopen.right] bind 0x6000:01 %IB4 "
                            "write the same input"), "%s", e);
    o->close(st);
    st = o->create();
    CO("canopen.left", "id", "1"); CO("canopen.right", "id", "2");
    CO("canopen.left", "bind", "0x6000:01.3 %IX2.0"); CO("canopen.right", "ok", "%IX2.0");
    ck_assert_int_ne(o->open(st, &img, 1000000, e, sizeof e), 0);
    ck_assert_msg(strstr(e, "[canopen.left] bind 0x6000:01.3 %IX2.0 and [canopen.right] ok %IX2.0"), "%s", e);
    o->close(st);
    st = o->create();              /* apart, and one %QB to both nodes: on to the bus (none here) */
    CO("canopen.left", "id", "1"); CO("canopen.right", "id", "2"); CO("canopen", "interface", "nocan9");
    CO("canopen.left", "bind", "0x6000:01 %IB4"); CO("canopen.right", "bind", "0x6000:01 %IB5");
    CO("canopen.left", "bind", "0x6200:01 %QB4"); CO("canopen.right", "bind", "0x6200:01 %QB4");
    ck_assert_int_ne(o->open(st, &img, 1000000, e, sizeof e), 0);
    ck_assert_msg(!strstr(e, "same input") && strstr(e, "nocan9"), "%s", e);
    o->close(st);
#undef CO
    bad("[io]\nbackend = canopen\n[canopen.a]\nid = 3\nid = 4\n",
        "plant.ini:5: [canopen.a] id: given twice (first on line 4)");
}
END_TEST

int main(void)
{
    Suite *s = suite_create("config");
    TCase *t = tcase_create("ini");
    tcase_add_test(t, defaults);
    tcase_add_test(t, good_file);
    tcase_add_test(t, sim_good);
    tcase_add_test(t, sim_modes);
    tcase_add_test(t, sim_modes_run);
    tcase_add_test(t, sim_master_markers);
    tcase_add_test(t, sim_master_follow);
    tcase_add_test(t, several_backends);
    tcase_add_test(t, modbus_io_keys);
    tcase_add_test(t, modbus_rtu_keys);
    tcase_add_test(t, sim_clock);
    tcase_add_test(t, syntax);
    tcase_add_test(t, unknown);
    tcase_add_test(t, values);
    tcase_add_test(t, first_error_wins);
    tcase_add_test(t, missing_file);
    tcase_add_test(t, decimal);
    tcase_add_test(t, bind_names);
    tcase_add_test(t, bind_host);
    tcase_add_test(t, cpu_host);
    tcase_add_test(t, retain_host);
    tcase_add_test(t, folder);
    tcase_add_test(t, long_lines);
    tcase_add_test(t, whole);
    tcase_add_test(t, messages);
    tcase_add_test(t, robust);
    tcase_add_test(t, careless_backend);
    suite_add_tcase(s, t);
    return check_run(s);
}

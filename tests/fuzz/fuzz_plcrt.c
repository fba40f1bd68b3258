/*
** fuzz_plcrt: libFuzzer target for what plcrt takes from outside while it
** runs. The first byte picks the input:
**
**   even: a stream of Modbus request PDUs ([length][PDU] records) served by
**         the map and the trace/forcing block (mbmap.h, tracemb.h) exactly
**         as the server thread does, a scan cycle (writes landed, forcing,
**         trace sample, image published) after every few requests. Every
**         reply must be a well-formed PDU: the function code, or it with
**         0x80 and an exception code 1..6, within MB_PDU_MAX bytes.
**   odd:  a retain file's body, given its valid CRC-32 (so that the parser
**         behind the checksum is reached), loaded into a program's
**         retained variables (retain.h).
**
** Anything the sanitizers see, a hang or a malformed reply is a finding.
*/
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "config.h"
#include "log.h"
#include "mbmap.h"
#include "retain.h"
#include "tracemb.h"

static int32_t v_dint;
static int16_t v_int;
static uint8_t v_bool;
static float v_real;
static double v_lreal;
static struct { long s, ns; } v_time;
static const plc_var vars[] = {
    { "CONFIG0.RES0.INST0.D", "DINT", 0, 0, 4, &v_dint },
    { "CONFIG0.RES0.INST0.I", "INT", 0, 0, 2, &v_int },
    { "CONFIG0.RES0.INST0.B", "BOOL", 0, 0, 1, &v_bool },
    { "CONFIG0.RES0.INST0.R", "REAL", 0, 0, 4, &v_real },
    { "CONFIG0.RES0.INST0.L", "LREAL", 0, 0, 8, &v_lreal },
    { "CONFIG0.RES0.INST0.T", "TIME", 0, 0, sizeof v_time, &v_time },
};
static const plc_program prog = { "CONFIG0", NULL, NULL, NULL, NULL, vars, 6 };
static const char *symbols =
    "[modbus.symbols]\n"
    "CONFIG0.RES0.INST0.D = holding 9000 rw\n"
    "CONFIG0.RES0.INST0.I = holding 9002\n"
    "CONFIG0.RES0.INST0.B = coil 9000 rw\n"
    "CONFIG0.RES0.INST0.R = holding 9004 rw\n"
    "CONFIG0.RES0.INST0.L = holding 9010 rw\n"
    "CONFIG0.RES0.INST0.D = input 3000\n";

static plc_config cfg;
static mb_shared *m;
static trace *tr;
static forcing *fo;
static tracemb *tb;
static char retain_path[64];

static void init(void)
{
    char err[700];
    plc_log_level(LOG_ERROR);                 /* the forcing log would drown the output */
    if (config_defaults(&cfg, err, sizeof err) || config_load_string(&cfg, "fuzz.ini", symbols, err, sizeof err)
        || !(m = mb_new(&cfg, &prog, err, sizeof err))) {
        fprintf(stderr, "fuzz_plcrt: set-up: %s\n", err);
        abort();
    }
    tr = trace_new(TRACE_MIN_SAMPLES * 4);
    fo = force_new(&prog, 1);
    tb = tb_new(tr, fo, &prog, 1000000);
    if (!tr || !fo || !tb) abort();
    m->block = tb_block(tb);
    mb_publish(m, &plc_img, NULL);
    snprintf(retain_path, sizeof retain_path, "/tmp/fuzz_plcrt-%d.retain", (int)getpid());
}

static uint32_t cycles;

static void cycle(void)
{
    mb_flush(m);
    mb_apply(m, &plc_img);
    force_begin(fo);
    force_apply(fo, FORCE_AFTER_INPUTS);
    v_dint += 3;                              /* the program */
    force_apply(fo, FORCE_AFTER_PROGRAM);
    trace_cycle(tr, cycles, cycles);
    cycles++;
    mb_publish(m, &plc_img, NULL);
}

static void modbus(const uint8_t *d, size_t n)
{
    uint8_t rsp[MB_PDU_MAX + 16];
    int k = 0;
    while (n) {
        size_t len = d[0];
        d++, n--;
        if (len > n) len = n;
        if (len == 0 || len > MB_PDU_MAX) { cycle(); continue; }
        memset(rsp, 0xEE, sizeof rsp);
        size_t r = mb_process(m, d, len, rsp);
        if (r < 2 || r > MB_PDU_MAX) abort();
        if (rsp[0] == (d[0] | 0x80)) {
            if (r != 2 || rsp[1] < 1 || rsp[1] > 6) abort();
        } else if (rsp[0] != d[0] || (d[0] & 0x80)) {
            abort();
        }
        d += len, n -= len;
        if (++k % 3 == 0) cycle();
    }
    cycle();
}

static void retain(const uint8_t *d, size_t n)
{
    static uint8_t buf[1 << 16];
    if (n + 4 > sizeof buf) n = sizeof buf - 4;
    memcpy(buf, d, n);
    uint32_t crc = retain_crc32(buf, n);
    memcpy(buf + n, &crc, 4);
    FILE *f = fopen(retain_path, "wb");
    if (!f) abort();
    fwrite(buf, 1, n + 4, f);
    fclose(f);
    uint8_t blob[40];
    retain_var v[3] = { { vars[0].path, "DINT", &v_dint, 4 }, { vars[4].path, "LREAL", &v_lreal, 8 },
                        { "CONFIG0.RES0.INST0.BLOB", "ARR", blob, sizeof blob } };
    uint64_t gen;
    char err[600];
    int r = retain_load_file(retain_path, v, 3, &gen, err, sizeof err);
    if (r < -1 || r > 2) abort();
    unlink(retain_path);
}

int LLVMFuzzerTestOneInput(const uint8_t *d, size_t n)
{
    if (!m) init();
    if (!n) return 0;
    if (d[0] & 1) retain(d + 1, n - 1);
    else modbus(d + 1, n - 1);
    return 0;
}

/* The master's node start-up, process data, heartbeat and EMCY handling,
 * driven frame by frame by a scripted node (a little object dictionary
 * that answers SDO requests the way CiA 301 servers do). */
#include <check.h>
#include <stdio.h>
#include <string.h>
#include "co_master.h"

#define T0 5000000000ull

static char logbuf[8192];
static void logcb(void *ctx, int err, const char *msg)
{
    (void)ctx;
    size_t n = strlen(logbuf);
    snprintf(logbuf + n, sizeof logbuf - n, "%s%s\n", err ? "E " : "I ", msg);
}

/* scripted node: a tiny object dictionary of 32-bit values */
typedef struct { uint16_t index; uint8_t sub; uint32_t value; } entry;
typedef struct {
    uint8_t id;
    uint32_t device_type;
    entry od[160];
    int n;
    int started, resets, silent;
    int guarded;            /* answers node guarding RTRs */
    uint8_t toggle;
} fake;

static entry *od(fake *f, uint16_t index, uint8_t sub)
{
    for (int i = 0; i < f->n; i++)
        if (f->od[i].index == index && f->od[i].sub == sub)
            return &f->od[i];
    f->od[f->n] = (entry){ index, sub, 0 };
    return &f->od[f->n++];
}

static co_frame frame(uint32_t id, int len, const uint8_t *d)
{
    co_frame f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.len = (uint8_t)len;
    if (len)
        memcpy(f.data, d, (size_t)len);
    return f;
}

/* answer one frame from the master; returns 1 with a reply in *r */
static int serve(fake *fk, const co_frame *in, co_frame *r)
{
    if (fk->silent)
        return 0;
    if (in->rtr && in->id == 0x700u + fk->id && fk->guarded) {
        *r = frame(0x700u + fk->id, 1, (uint8_t[]){ (uint8_t)(0x05 | fk->toggle) });
        fk->toggle ^= 0x80;
        return 1;
    }
    if (in->id == 0 && (in->data[0] == 0x82 || in->data[0] == 0x81))
        fk->toggle = 0;
    if (in->id == 0 && (in->data[1] == fk->id || in->data[1] == 0)) {
        if (in->data[0] == 0x82 || in->data[0] == 0x81) {
            fk->resets++;
            *r = frame(0x700u + fk->id, 1, (uint8_t[]){ 0x00 });
            return 1;
        }
        if (in->data[0] == 0x01)
            fk->started++;
        return 0;
    }
    if (in->id != 0x600u + fk->id)
        return 0;
    uint16_t index = co_get16(in->data + 1);
    uint8_t sub = in->data[3], cmd = in->data[0];
    uint8_t d[8] = { 0 };
    memcpy(d + 1, in->data + 1, 3);
    if (cmd == 0x40) {
        uint32_t v = index == 0x1000 ? fk->device_type : od(fk, index, sub)->value;
        d[0] = 0x43;
        co_put32(d + 4, v);
    } else if (index >= 0x2000 && index < 0x6000) {
        d[0] = 0x80;
        co_put32(d + 4, 0x06020000);
    } else if ((cmd & 0xE3) == 0x23) {
        unsigned n = 4 - ((cmd >> 2) & 3);
        uint32_t v = 0;
        memcpy(&v, in->data + 4, n);           /* little-endian host */
        od(fk, index, sub)->value = v;
        d[0] = 0x60;
    } else {
        d[0] = 0x80;
        co_put32(d + 4, 0x05040001);
    }
    *r = frame(0x580u + fk->id, 8, d);
    return 1;
}

/* run the bus: deliver every queued frame to the fakes and their replies
 * back to the master, until quiet */
static int pump(co_master *m, fake *fk, int nf, co_time now, co_frame *seen, int maxseen)
{
    co_frame f, r;
    int k = 0;
    while (co_master_pop(m, &f)) {
        if (seen && k < maxseen)
            seen[k] = f;
        k++;
        for (int i = 0; i < nf; i++)
            if (serve(&fk[i], &f, &r))
                co_master_rx(m, &r, now);
    }
    return k;
}

static uint32_t val(fake *f, uint16_t index, uint8_t sub) { return od(f, index, sub)->value; }

START_TEST(startup_configures_cia401_defaults)
{
    co_master m;
    co_node n[1];
    fake fk = { .id = 5, .device_type = 0x000F0191 };
    logbuf[0] = 0;
    co_node_cfg_cia401(&n[0].cfg, 5);
    n[0].cfg.device_type = 0x000F0191;
    n[0].cfg.check_type = 1;
    co_master_init(&m, n, 1, 1);
    m.log = logcb;
    co_master_start(&m, T0);
    co_frame first;
    ck_assert(co_master_pop(&m, &first));
    ck_assert_uint_eq(first.id, 0);                  /* reset communication */
    ck_assert_uint_eq(first.data[0], 0x82);
    ck_assert_uint_eq(first.data[1], 5);
    co_frame r;
    ck_assert(serve(&fk, &first, &r));
    co_master_rx(&m, &r, T0);
    pump(&m, &fk, 1, T0, NULL, 0);
    ck_assert(co_master_settled(&m));
    ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    ck_assert_int_eq(fk.started, 1);
    ck_assert_uint_eq(n[0].device_type, 0x000F0191);
    /* the node's dictionary now holds the CiA 401 mappings, by hand: */
    ck_assert_uint_eq(val(&fk, 0x1400, 1), 0x205);
    ck_assert_uint_eq(val(&fk, 0x1401, 1), 0x305);
    ck_assert_uint_eq(val(&fk, 0x1402, 1), 0x80000405);      /* unused: invalid */
    ck_assert_uint_eq(val(&fk, 0x1800, 1), 0x185);
    ck_assert_uint_eq(val(&fk, 0x1801, 1), 0x285);
    ck_assert_uint_eq(val(&fk, 0x1803, 1), 0x80000485);
    ck_assert_uint_eq(val(&fk, 0x1800, 2), 1);
    ck_assert_uint_eq(val(&fk, 0x1600, 0), 8);
    ck_assert_uint_eq(val(&fk, 0x1600, 1), 0x62000108);
    ck_assert_uint_eq(val(&fk, 0x1600, 8), 0x62000808);
    ck_assert_uint_eq(val(&fk, 0x1A00, 3), 0x60000308);
    ck_assert_uint_eq(val(&fk, 0x1601, 0), 4);
    ck_assert_uint_eq(val(&fk, 0x1601, 2), 0x64110210);
    ck_assert_uint_eq(val(&fk, 0x1A01, 4), 0x64010410);
    ck_assert_uint_eq(val(&fk, 0x1017, 0), 100);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 5: configured"));
}
END_TEST

static void boot(co_master *m, co_node *n, int nn, fake *fk, int nf)
{
    co_master_init(m, n, nn, 1);
    m->log = logcb;
    co_master_start(m, T0);
    pump(m, fk, nf, T0, NULL, 0);
}

START_TEST(silent_node_reported_by_id_and_object)
{
    co_master m;
    co_node n[1];
    fake fk = { .id = 9, .silent = 1 };
    logbuf[0] = 0;
    co_node_cfg_cia401(&n[0].cfg, 9);
    boot(&m, n, 1, &fk, 1);
    ck_assert(!co_master_settled(&m));
    co_master_tick(&m, T0 + 1999 * CO_MS);
    ck_assert_int_eq(n[0].phase, CO_PH_WAIT_BOOT);
    co_master_tick(&m, T0 + 2000 * CO_MS);           /* boot time-out: try SDO */
    ck_assert_int_eq(n[0].phase, CO_PH_CHECK_TYPE);
    co_frame f;
    ck_assert(co_master_pop(&m, &f));
    ck_assert_uint_eq(f.id, 0x609);
    co_master_tick(&m, T0 + 2500 * CO_MS);           /* SDO time-out */
    ck_assert_int_eq(n[0].phase, CO_PH_FAILED);
    ck_assert(co_master_settled(&m));
    ck_assert(n[0].fault & CO_F_START);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 9 does not answer: SDO upload of object 0x1000:00 timed out"));
    /* retried later, and it comes up */
    fk.silent = 0;
    co_master_tick(&m, T0 + 7499 * CO_MS);
    ck_assert_int_eq(n[0].phase, CO_PH_FAILED);
    co_master_tick(&m, T0 + 7500 * CO_MS);
    pump(&m, &fk, 1, T0 + 7500 * CO_MS, NULL, 0);
    ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    ck_assert(!(n[0].fault & CO_F_START));
}
END_TEST

START_TEST(wrong_device_type_refused)
{
    co_master m;
    co_node n[1];
    fake fk = { .id = 4, .device_type = 0x00020192 };      /* a CiA 402 drive */
    logbuf[0] = 0;
    co_node_cfg_cia401(&n[0].cfg, 4);
    n[0].cfg.check_type = 1;
    boot(&m, n, 1, &fk, 1);
    ck_assert_int_eq(n[0].phase, CO_PH_FAILED);
    ck_assert(n[0].fault & CO_F_TYPE);
    ck_assert_int_eq(fk.started, 0);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 4: device type 0x00020192 in object 0x1000, expected 0x00000191"));
}
END_TEST

START_TEST(sdo_abort_during_config_reported)
{
    co_master m;
    co_node n[1];
    fake fk = { .id = 6, .device_type = 0x191 };
    logbuf[0] = 0;
    co_node_cfg_cia401(&n[0].cfg, 6);
    n[0].cfg.nextra = 1;                                   /* an object the node lacks */
    n[0].cfg.extra[0] = (co_sdo_write){ 0x2100, 1, 3, 7 };
    boot(&m, n, 1, &fk, 1);
    ck_assert_int_eq(n[0].phase, CO_PH_FAILED);
    ck_assert(n[0].fault & CO_F_SDO);
    ck_assert_uint_eq(n[0].last_abort, 0x06020000);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 6: SDO download of object 0x2100:01 aborted by the node: "
                                 "0x06020000 object does not exist in the object dictionary"));
}
END_TEST

START_TEST(process_data_and_sync)
{
    co_master m;
    co_node n[2];
    fake fk[2] = { { .id = 1, .device_type = 0x191 }, { .id = 2, .device_type = 0x191 } };
    co_node_cfg_cia401(&n[0].cfg, 1);
    co_node_cfg_cia401(&n[1].cfg, 2);
    boot(&m, n, 2, fk, 2);
    ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    ck_assert_int_eq(n[1].phase, CO_PH_RUN);
    /* outputs: RPDO1 of node 2 carries 0x6200:01..08, RPDO2 0x6411:01..04 */
    n[1].tx[0][0] = 0xA5;
    co_bits_put(n[1].tx[1], 16, 16, (uint16_t)-1000);
    co_master_cycle(&m, T0);
    co_frame seen[16];
    int k = pump(&m, fk, 2, T0, seen, 16);
    ck_assert_int_eq(k, 5);                 /* 2 RPDOs per node, then SYNC */
    ck_assert_uint_eq(seen[0].id, 0x201);
    ck_assert_uint_eq(seen[2].id, 0x202);
    ck_assert_uint_eq(seen[2].len, 8);
    ck_assert_uint_eq(seen[2].data[0], 0xA5);
    ck_assert_uint_eq(seen[3].id, 0x302);
    ck_assert_uint_eq(seen[3].data[2], 0x18);      /* -1000 = 0xFC18 */
    ck_assert_uint_eq(seen[3].data[3], 0xFC);
    ck_assert_uint_eq(seen[4].id, 0x080);
    /* inputs: TPDO2 of node 1 */
    co_frame t = frame(0x281, 8, (uint8_t[]){ 0x10, 0x27, 0, 0, 0, 0, 0, 0x80 });
    co_master_rx(&m, &t, T0);
    ck_assert_uint_eq(n[0].rx_new, 2);
    ck_assert_int_eq((int16_t)co_bits_get(n[0].rx[1], 0, 16), 10000);
    ck_assert_int_eq(co_bits_sext(co_bits_get(n[0].rx[1], 48, 16), 16), -32768);
    /* a TPDO shorter than its mapping is ignored, and said so once (then
    ** every 1000th): its inputs would otherwise freeze without a word */
    logbuf[0] = 0;
    t = frame(0x181, 2, (uint8_t[]){ 1, 2 });
    co_master_rx(&m, &t, T0);
    ck_assert_uint_eq(n[0].rx_new, 2);
    ck_assert_msg(strstr(logbuf, "E node 1: TPDO1 of 2 byte(s), its mapping needs 8: ignored"), "%s", logbuf);
    ck_assert_msg(strstr(logbuf, "mapping 0x1A00 differs from the configuration's tpdo1"), "%s", logbuf);
    logbuf[0] = 0;
    co_master_rx(&m, &t, T0);
    ck_assert_str_eq(logbuf, "");
    ck_assert_uint_eq(n[0].short_pdos, 2);
    /* the node's status says its inputs are stale (bit 6) until a good one */
    ck_assert(n[0].fault & CO_F_SHORT);
    t = frame(0x181, 8, (uint8_t[]){ 1, 2, 3, 4, 5, 6, 7, 8 });
    co_master_rx(&m, &t, T0);
    ck_assert(!(n[0].fault & CO_F_SHORT));
}
END_TEST

START_TEST(heartbeat_lost_outputs_safe_then_restart)
{
    co_master m;
    co_node n[2];
    fake fk[2] = { { .id = 1, .device_type = 0x191 }, { .id = 2, .device_type = 0x191 } };
    logbuf[0] = 0;
    co_node_cfg_cia401(&n[0].cfg, 1);
    co_node_cfg_cia401(&n[1].cfg, 2);
    boot(&m, n, 2, fk, 2);
    co_frame hb1 = frame(0x701, 1, (uint8_t[]){ 0x05 }), hb2 = frame(0x702, 1, (uint8_t[]){ 0x05 });
    co_time t = T0;
    for (int i = 0; i < 3; i++, t += 100 * CO_MS) {   /* both beat every 100 ms */
        co_master_rx(&m, &hb1, t);
        co_master_rx(&m, &hb2, t);
        co_master_tick(&m, t);
    }
    /* node 2 falls silent after its beat at t-100 ms; consumer time 250 ms */
    co_time last2 = t - 100 * CO_MS;
    for (; t <= last2 + 250 * CO_MS; t += 10 * CO_MS) {
        if ((t - T0) % (100 * CO_MS) == 0)
            co_master_rx(&m, &hb1, t);
        co_master_tick(&m, t);
        ck_assert_int_eq(n[1].phase, CO_PH_RUN);
    }
    co_master_tick(&m, last2 + 251 * CO_MS);
    ck_assert_int_eq(n[1].phase, CO_PH_LOST);
    ck_assert(n[1].fault & CO_F_LOST);
    ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 2: heartbeat lost"));
    /* its outputs go out as zeros whatever the program writes */
    n[1].tx[0][0] = 0xFF;
    n[0].tx[0][0] = 0x0F;
    co_master_cycle(&m, t);
    co_frame seen[8];
    ck_assert_int_eq(pump(&m, fk, 2, t, seen, 8), 5);
    ck_assert_uint_eq(seen[0].data[0], 0x0F);
    ck_assert_uint_eq(seen[2].id, 0x202);
    ck_assert_uint_eq(seen[2].data[0], 0x00);
    /* heard again: reset, reconfigured, running */
    int resets = fk[1].resets;
    co_master_rx(&m, &hb2, t + 10 * CO_MS);
    pump(&m, fk, 2, t + 10 * CO_MS, NULL, 0);
    ck_assert_int_eq(fk[1].resets, resets + 1);
    ck_assert_int_eq(n[1].phase, CO_PH_RUN);
    ck_assert(!(n[1].fault & CO_F_LOST));
    ck_assert_uint_eq(n[1].hb_lost, 1);
}
END_TEST

START_TEST(guarding_lost_outputs_safe_then_restart)
{
    co_master m;
    co_node n[1];
    fake fk = { .id = 3, .device_type = 0x191, .guarded = 1 };
    logbuf[0] = 0;
    co_node_cfg_cia401(&n[0].cfg, 3);
    n[0].cfg.hb_producer_ms = 0;
    n[0].cfg.hb_consumer_ms = 0;
    n[0].cfg.guard_ms = 100;
    boot(&m, n, 1, &fk, 1);
    ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    ck_assert_uint_eq(val(&fk, 0x100C, 0), 100);      /* the node guards us likewise */
    ck_assert_uint_eq(val(&fk, 0x100D, 0), 3);
    co_time t = T0;
    for (; t < T0 + 1000 * CO_MS; t += 10 * CO_MS) {   /* answering: never lost */
        co_master_tick(&m, t);
        pump(&m, &fk, 1, t, NULL, 0);
    }
    ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    ck_assert_uint_eq(n[0].guard.answers, 10);         /* one RTR per 100 ms */
    ck_assert_uint_eq(n[0].guard.toggle_errors, 0);
    /* silent from t: the last answer came at t - 10 ms; lost after 300 ms */
    co_time last = n[0].guard.last;
    fk.guarded = 0;
    for (; t <= last + 300 * CO_MS; t += 10 * CO_MS) {
        co_master_tick(&m, t);
        pump(&m, &fk, 1, t, NULL, 0);
        ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    }
    co_master_tick(&m, last + 301 * CO_MS);
    ck_assert_int_eq(n[0].phase, CO_PH_LOST);
    ck_assert(n[0].fault & CO_F_LOST);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 3: no answer to node guarding for 300 ms "
                                         "(guard time 100 ms x life factor 3)"));
    n[0].tx[0][0] = 0xFF;
    co_master_cycle(&m, t);
    co_frame seen[4];
    pump(&m, &fk, 1, t, seen, 4);
    ck_assert_uint_eq(seen[0].id, 0x203);
    ck_assert_uint_eq(seen[0].data[0], 0x00);          /* outputs safe */
    /* it answers again, its toggle bit where it left off: one answer may be
     * refused for its toggle, the next is good; then it is reset */
    int resets = fk.resets;
    fk.guarded = 1;
    for (int i = 0; i < 40 && n[0].phase != CO_PH_RUN; i++, t += 10 * CO_MS) {
        co_master_tick(&m, t);
        pump(&m, &fk, 1, t, NULL, 0);
    }
    ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    ck_assert_int_eq(fk.resets, resets + 1);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 3: answers node guarding again"));
}
END_TEST

START_TEST(unexpected_bootup_reconfigures)
{
    co_master m;
    co_node n[1];
    fake fk = { .id = 3, .device_type = 0x191 };
    logbuf[0] = 0;
    co_node_cfg_cia401(&n[0].cfg, 3);
    boot(&m, n, 1, &fk, 1);
    ck_assert_int_eq(fk.started, 1);
    /* the node resets itself: its dictionary back to power-on values */
    fk.n = 0;
    co_frame b = frame(0x703, 1, (uint8_t[]){ 0x00 });
    co_master_rx(&m, &b, T0 + CO_MS);
    ck_assert_int_eq(n[0].phase, CO_PH_CHECK_TYPE);
    pump(&m, &fk, 1, T0 + CO_MS, NULL, 0);
    ck_assert_int_eq(n[0].phase, CO_PH_RUN);
    ck_assert_int_eq(fk.started, 2);
    ck_assert_uint_eq(n[0].unexpected_boot, 1);
    ck_assert(n[0].fault & CO_F_BOOT);
    ck_assert_uint_eq(val(&fk, 0x1601, 1), 0x64110110);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 3: unexpected boot-up while operational (1 so far): reconfiguring"));
}
END_TEST

START_TEST(emcy_logged_and_flagged)
{
    co_master m;
    co_node n[1];
    fake fk = { .id = 3, .device_type = 0x191 };
    logbuf[0] = 0;
    co_node_cfg_cia401(&n[0].cfg, 3);
    boot(&m, n, 1, &fk, 1);
    co_frame e = frame(0x083, 8, (uint8_t[]){ 0x10, 0x32, 0x05, 1, 2, 3, 4, 5 });
    co_master_rx(&m, &e, T0);
    ck_assert(n[0].fault & CO_F_EMCY);
    ck_assert_uint_eq(n[0].emcy_count, 1);
    ck_assert_uint_eq(n[0].last_emcy.code, 0x3210);
    ck_assert_ptr_nonnull(strstr(logbuf, "node 3: EMCY 0x3210 (voltage), error register 0x05 (generic voltage)"));
    e = frame(0x083, 8, (uint8_t[]){ 0, 0, 0, 0, 0, 0, 0, 0 });
    co_master_rx(&m, &e, T0);
    ck_assert(!(n[0].fault & CO_F_EMCY));
    ck_assert_uint_eq(n[0].emcy_count, 1);
    /* an EMCY too short for its error code: ignored before, now said */
    logbuf[0] = 0;
    e = frame(0x083, 1, (uint8_t[]){ 0x10 });
    co_master_rx(&m, &e, T0);
    ck_assert_msg(strstr(logbuf, "E node 3: EMCY frame of 1 byte(s), 8 expected: no error code to report"), "%s",
                  logbuf);
    /* bus-off error frame */
    co_frame bo = frame(CO_ERR_FLAG | 0x40, 8, (uint8_t[]){ 0, 0, 0, 0, 0, 0, 0, 0 });
    co_master_rx(&m, &bo, T0);
    ck_assert_int_eq(m.bus, CO_BUS_OFF);
    ck_assert_uint_eq(m.busoff_count, 1);
    ck_assert_ptr_nonnull(strstr(logbuf, "CAN bus: bus-off"));
}
END_TEST

Suite *master_suite(void)
{
    Suite *s = suite_create("canopen_master");
    TCase *t = tcase_create("master");
    tcase_add_test(t, startup_configures_cia401_defaults);
    tcase_add_test(t, silent_node_reported_by_id_and_object);
    tcase_add_test(t, wrong_device_type_refused);
    tcase_add_test(t, sdo_abort_during_config_reported);
    tcase_add_test(t, process_data_and_sync);
    tcase_add_test(t, heartbeat_lost_outputs_safe_then_restart);
    tcase_add_test(t, guarding_lost_outputs_safe_then_restart);
    tcase_add_test(t, unexpected_bootup_reconfigures);
    tcase_add_test(t, emcy_logged_and_flagged);
    suite_add_tcase(s, t);
    return s;
}

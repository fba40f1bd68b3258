#include <stdio.h>
#include <string.h>
#include "co_master.h"

/* error classes of Linux error frames (linux/can/error.h) */
#define ERR_CRTL 0x04u
#define ERR_BUSOFF 0x40u
#define ERR_RESTARTED 0x100u
#define CRTL_WARNING 0x0Cu      /* rx/tx warning bits of data[1] */
#define CRTL_PASSIVE 0x30u      /* rx/tx passive bits of data[1] */

static void logf_(co_master *m, int err, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void logf_(co_master *m, int err, const char *fmt, ...)
{
    char buf[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (m->log)
        m->log(m->log_ctx, err, buf);
}

static void push(co_master *m, const co_frame *f)
{
    unsigned n = sizeof m->q / sizeof m->q[0];
    if (m->qt - m->qh >= n) {
        m->tx_dropped++;
        return;
    }
    m->q[m->qt++ % n] = *f;
}

int co_master_pop(co_master *m, co_frame *f)
{
    if (m->qh == m->qt)
        return 0;
    *f = m->q[m->qh++ % (sizeof m->q / sizeof m->q[0])];
    return 1;
}

const char *co_phase_name(int phase)
{
    static const char *n[] = { "idle", "waiting for boot-up", "checking device type",
        "configuring", "operational", "lost", "failed" };
    return phase >= 0 && phase <= CO_PH_FAILED ? n[phase] : "?";
}

void co_node_cfg_cia401(co_node_cfg *c, uint8_t id)
{
    memset(c, 0, sizeof *c);
    c->id = id;
    c->device_type = 0x00000191;        /* CiA 401 */
    c->hb_producer_ms = 100;
    c->hb_consumer_ms = 250;
    c->life_factor = 3;
    for (unsigned i = 0; i < CO_PDO_PER_NODE; i++) {
        co_pdo_cia401_default(0, i, &c->rpdo[i]);
        co_pdo_cia401_default(1, i, &c->tpdo[i]);
    }
}

void co_master_init(co_master *m, co_node *nodes, int nnodes, unsigned sync_every)
{
    memset(m, 0, sizeof *m);
    m->nodes = nodes;
    m->nnodes = nnodes;
    m->boot_timeout = 2000 * CO_MS;
    m->sdo_timeout = 500 * CO_MS;
    m->retry_interval = 5000 * CO_MS;
    co_sync_init(&m->sync, sync_every, 0);
    for (int i = 0; i < nnodes; i++) {
        co_node *n = &nodes[i];
        co_node_cfg c = n->cfg;
        memset(n, 0, sizeof *n);
        n->cfg = c;
        co_sdo_init(&n->sdo, c.id, m->sdo_timeout);
        co_hb_init(&n->hb, c.id, (co_time)c.hb_consumer_ms * CO_MS);
        co_guard_init(&n->guard, c.id, (co_time)c.guard_ms * CO_MS, c.life_factor);
    }
}

co_node *co_master_node(co_master *m, uint8_t id)
{
    for (int i = 0; i < m->nnodes; i++)
        if (m->nodes[i].cfg.id == id)
            return &m->nodes[i];
    return NULL;
}

/* build the list of configuration writes */
static void plan(co_node *n)
{
    int k = 0;
    for (int tx = 0; tx < 2; tx++)
        for (unsigned i = 0; i < CO_PDO_PER_NODE; i++) {
            int r = co_pdo_config(tx, i, n->cfg.id, tx ? &n->cfg.tpdo[i] : &n->cfg.rpdo[i],
                                  n->w + k, CO_MAX_WRITES - k);
            if (r > 0)
                k += r;
        }
    if (n->cfg.hb_producer_ms && k < CO_MAX_WRITES)
        n->w[k++] = (co_sdo_write){ 0x1017, 0, 2, n->cfg.hb_producer_ms };
    if (n->cfg.guard_ms && k + 1 < CO_MAX_WRITES) {
        /* the node guards the master with the same numbers (life guarding) */
        n->w[k++] = (co_sdo_write){ 0x100C, 0, 2, n->cfg.guard_ms };
        n->w[k++] = (co_sdo_write){ 0x100D, 0, 1, n->guard.life };
    }
    for (unsigned i = 0; i < n->cfg.nextra && k < CO_MAX_WRITES; i++)
        n->w[k++] = n->cfg.extra[i];
    n->nw = (uint8_t)k;
    n->wi = 0;
}

static void nmt(co_master *m, co_node *n, uint8_t cmd)
{
    co_frame f;
    if (!co_nmt_frame(&f, cmd, n->cfg.id))
        push(m, &f);
}

static void fail(co_master *m, co_node *n, co_time now, int flag)
{
    n->phase = CO_PH_FAILED;
    n->fault |= (uint8_t)(CO_F_START | flag);
    n->retry_at = now + m->retry_interval;
    memset(n->tx, 0, sizeof n->tx);
}

static void reset_comm(co_master *m, co_node *n, co_time now)
{
    n->guard.active = 0;            /* the node's toggle starts again at 0 */
    n->phase = CO_PH_WAIT_BOOT;
    n->deadline = now + m->boot_timeout;
    n->starts++;
    nmt(m, n, CO_NMT_RESET_COMM);
}

/* the node is in pre-operational after a boot-up: read 0x1000 */
static void check_type(co_master *m, co_node *n, co_time now)
{
    co_frame f;
    n->phase = CO_PH_CHECK_TYPE;
    n->hb.active = 0;
    n->sdo.status = CO_SDO_IDLE;
    memset(n->ubuf, 0, sizeof n->ubuf);
    if (!co_sdo_upload(&n->sdo, 0x1000, 0, n->ubuf, sizeof n->ubuf, now, &f))
        push(m, &f);
}

static void next_write(co_master *m, co_node *n, co_time now)
{
    co_frame f;
    if (n->wi >= n->nw) {           /* configured: start */
        nmt(m, n, CO_NMT_START);
        n->phase = CO_PH_RUN;
        n->fault &= (uint8_t)~(CO_F_LOST | CO_F_START | CO_F_TYPE | CO_F_SDO);
        n->hb.active = 1;
        n->hb.lost = 0;
        n->hb.last = now;
        co_guard_start(&n->guard, now);
        logf_(m, 0, "node %u: configured (%u SDO writes) and started", n->cfg.id, n->nw);
        return;
    }
    const co_sdo_write *w = &n->w[n->wi];
    co_put32(n->wbuf, w->value);
    if (!co_sdo_download(&n->sdo, w->index, w->sub, n->wbuf, w->size, now, &f))
        push(m, &f);
}

static void sdo_failed(co_master *m, co_node *n, co_time now, const char *what)
{
    n->sdo_errors++;
    n->last_abort = n->sdo.abort_code;
    n->fault |= CO_F_SDO;
    if (n->sdo.abort_code == CO_SDO_ABORT_TIMEOUT)
        logf_(m, 1, "node %u does not answer: SDO %s of object 0x%04X:%02X timed out",
              n->cfg.id, what, n->sdo.index, n->sdo.sub);
    else
        logf_(m, 1, "node %u: SDO %s of object 0x%04X:%02X aborted by %s: 0x%08X %s",
              n->cfg.id, what, n->sdo.index, n->sdo.sub, n->sdo.by_server ? "the node" : "the master",
              n->sdo.abort_code, co_sdo_abort_text(n->sdo.abort_code));
    fail(m, n, now, 0);
}

/* the SDO transfer of a starting node ended */
static void sdo_done(co_master *m, co_node *n, co_time now)
{
    if (n->sdo.status == CO_SDO_FAILED) {
        sdo_failed(m, n, now, n->phase == CO_PH_CHECK_TYPE ? "upload" : "download");
        return;
    }
    if (n->phase == CO_PH_CHECK_TYPE) {
        n->device_type = co_get32(n->ubuf);
        if (n->cfg.check_type && n->device_type != n->cfg.device_type) {
            logf_(m, 1, "node %u: device type 0x%08X in object 0x1000, expected 0x%08X",
                  n->cfg.id, n->device_type, n->cfg.device_type);
            fail(m, n, now, CO_F_TYPE);
            return;
        }
        n->phase = CO_PH_CONFIG;
        plan(n);
        next_write(m, n, now);
    } else if (n->phase == CO_PH_CONFIG) {
        n->wi++;
        next_write(m, n, now);
    }
}

void co_master_start(co_master *m, co_time now)
{
    for (int i = 0; i < m->nnodes; i++) {
        co_node *n = &m->nodes[i];
        memset(n->tx, 0, sizeof n->tx);
        reset_comm(m, n, now);
    }
}

int co_master_settled(const co_master *m)
{
    for (int i = 0; i < m->nnodes; i++) {
        int p = m->nodes[i].phase;
        if (p == CO_PH_WAIT_BOOT || p == CO_PH_CHECK_TYPE || p == CO_PH_CONFIG)
            return 0;
    }
    return 1;
}

static void bootup(co_master *m, co_node *n, co_time now)
{
    if (n->phase == CO_PH_WAIT_BOOT) {
        check_type(m, n, now);
        return;
    }
    if (n->phase == CO_PH_IDLE)
        return;
    n->unexpected_boot++;
    n->fault |= CO_F_BOOT;
    logf_(m, 1, "node %u: unexpected boot-up while %s (%u so far): reconfiguring",
          n->cfg.id, co_phase_name(n->phase), n->unexpected_boot);
    memset(n->tx, 0, sizeof n->tx);
    check_type(m, n, now);
}

static void emcy(co_master *m, co_node *n, const co_emcy *e)
{
    char reg[96];
    n->last_emcy = *e;
    if (e->code == 0) {
        n->fault &= (uint8_t)~CO_F_EMCY;
        logf_(m, 0, "node %u: EMCY error reset, error register 0x%02X", n->cfg.id, e->reg);
        return;
    }
    n->emcy_count++;
    n->fault |= CO_F_EMCY;
    logf_(m, 1, "node %u: EMCY 0x%04X (%s), error register 0x%02X (%s), data %02X %02X %02X %02X %02X",
          n->cfg.id, e->code, co_emcy_class(e->code), e->reg,
          co_emcy_reg_text(e->reg, reg, sizeof reg),
          e->msef[0], e->msef[1], e->msef[2], e->msef[3], e->msef[4]);
}

static void err_frame(co_master *m, const co_frame *f)
{
    uint32_t cls = f->id & ~CO_ERR_FLAG;
    m->err_frames++;
    if (cls & ERR_BUSOFF) {
        m->busoff_count++;
        co_master_bus(m, CO_BUS_OFF, "bus-off");
    } else if (cls & ERR_RESTARTED) {
        co_master_bus(m, CO_BUS_OK, "controller restarted");
    } else if (cls & ERR_CRTL && f->len > 1) {
        if (f->data[1] & CRTL_PASSIVE)
            co_master_bus(m, CO_BUS_PASSIVE, "error passive");
        else if (f->data[1] & CRTL_WARNING)
            co_master_bus(m, CO_BUS_WARNING, "error warning");
    }
}

void co_master_bus(co_master *m, int state, const char *why)
{
    if (state == m->bus)
        return;
    static const char *name[] = { "ok", "error warning", "error passive", "bus-off", "down" };
    logf_(m, state >= CO_BUS_PASSIVE, "CAN bus: %s (%s)", name[state], why);
    m->bus = (uint8_t)state;
}

/* an answer to node guarding */
static void guard_rx(co_master *m, co_node *n, const co_frame *f, co_time now)
{
    co_guard *g = &n->guard;
    switch (co_guard_rx(g, f, now)) {
    case CO_GUARD_BACK:
        if (n->phase == CO_PH_LOST) {
            logf_(m, 0, "node %u: answers node guarding again (%s): restarting it", n->cfg.id,
                  co_nmt_state_name(g->state));
            reset_comm(m, n, now);
        }
        break;
    case CO_GUARD_TOGGLE:
        if (g->toggle_errors % 100 == 1)
            logf_(m, 1, "node %u: node guarding answer with toggle bit %u, expected %u: not an answer "
                  "(%u so far)", n->cfg.id, (unsigned)(f->data[0] >> 7), (unsigned)(g->toggle >> 7),
                  (unsigned)g->toggle_errors);
        break;
    case CO_GUARD_STATE:
        if (n->phase == CO_PH_RUN && g->state != CO_ST_OPERATIONAL && g->answers > 1)
            logf_(m, 1, "node %u: left operational, now %s (node guarding)", n->cfg.id,
                  co_nmt_state_name(g->state));
        break;
    default:
        break;
    }
}

void co_master_rx(co_master *m, const co_frame *f, co_time now)
{
    if (f->id & CO_ERR_FLAG) {
        err_frame(m, f);
        return;
    }
    if (m->bus == CO_BUS_OFF || m->bus == CO_BUS_PASSIVE)
        co_master_bus(m, CO_BUS_OK, "frames received again");
    uint32_t fc = f->id & 0x780;
    uint8_t id = f->id & 0x7F;
    co_node *n = id ? co_master_node(m, id) : NULL;
    if (!n || f->rtr)
        return;
    co_frame out;
    if (fc == CO_FC_HB && n->guard.period && f->len >= 1 && (f->data[0] & 0x7F) != 0) {
        guard_rx(m, n, f, now);
    } else if (fc == CO_FC_HB) {
        int prev_op = n->was_op;
        n->was_op = f->len >= 1 && n->phase == CO_PH_RUN && (f->data[0] & 0x7F) == CO_ST_OPERATIONAL;
        switch (co_hb_rx(&n->hb, f, now)) {
        case CO_HB_BOOTUP:
            bootup(m, n, now);
            break;
        case CO_HB_BACK:
            if (n->phase == CO_PH_LOST) {
                logf_(m, 0, "node %u: heartbeat back (%s): restarting it", n->cfg.id,
                      co_nmt_state_name(n->hb.state));
                reset_comm(m, n, now);
            }
            break;
        case CO_HB_STATE:
            /* a heartbeat sent before our start command arrived is no news */
            if (n->phase == CO_PH_RUN && n->hb.state != CO_ST_OPERATIONAL && prev_op)
                logf_(m, 1, "node %u: left operational, now %s", n->cfg.id,
                      co_nmt_state_name(n->hb.state));
            break;
        default:
            break;
        }
    } else if (fc == CO_FC_SDO_TX) {
        int was = n->sdo.status;
        if (co_sdo_rx(&n->sdo, f, now, &out))
            push(m, &out);
        if (was == CO_SDO_BUSY && n->sdo.status != CO_SDO_BUSY)
            sdo_done(m, n, now);
    } else if (fc == CO_FC_EMCY) {
        co_emcy e;
        if (!co_emcy_decode(f, &e))
            emcy(m, n, &e);
        else                        /* too short for an error code: still news */
            logf_(m, 1, "node %u: EMCY frame of %u byte(s), 8 expected: no error code to report (the node "
                  "signals an emergency it does not describe, or sends on 0x%03X what is no EMCY)",
                  n->cfg.id, (unsigned)f->len, (unsigned)f->id);
    } else if (fc >= CO_FC_TPDO1 && fc < CO_FC_TPDO1 + 0x100 * CO_PDO_PER_NODE && (fc & 0x80)) {
        unsigned k = (fc - CO_FC_TPDO1) / 0x100;
        unsigned need = (co_pdo_bits(&n->cfg.tpdo[k]) + 7) / 8;
        if (n->phase == CO_PH_RUN && f->len >= need) {
            memcpy(n->rx[k], f->data, f->len);
            n->rx_new |= (uint8_t)(1 << k);
            n->rx_pdos++;
            n->short_mask &= (uint8_t)~(1 << k);
            if (!n->short_mask)
                n->fault &= (uint8_t)~CO_F_SHORT;
        } else if (n->phase == CO_PH_RUN) {
            /* its inputs keep their last values: never silently, and the
             * node's status says they are stale (bit 6) until a good one */
            n->short_mask |= (uint8_t)(1 << k);
            n->fault |= CO_F_SHORT;
            if (n->short_pdos++ % 1000 == 0)
                logf_(m, 1, "node %u: TPDO%u of %u byte(s), its mapping needs %u: ignored, the inputs it carries "
                      "keep their last values (%u such so far; the node's mapping 0x%04X differs from the "
                      "configuration's tpdo%u)", n->cfg.id, k + 1, (unsigned)f->len, need, (unsigned)n->short_pdos,
                      0x1A00 + k, k + 1);
        }
    }
}

void co_master_tick(co_master *m, co_time now)
{
    co_frame out;
    for (int i = 0; i < m->nnodes; i++) {
        co_node *n = &m->nodes[i];
        switch (n->phase) {
        case CO_PH_WAIT_BOOT:
            if (now >= n->deadline) {
                /* no boot-up: the node may be up already; try to read it */
                logf_(m, 1, "node %u: no boot-up within %llu ms after reset communication",
                      n->cfg.id, (unsigned long long)(m->boot_timeout / CO_MS));
                check_type(m, n, now);
            }
            break;
        case CO_PH_CHECK_TYPE:
        case CO_PH_CONFIG:
            if (co_sdo_tick(&n->sdo, now, &out)) {
                push(m, &out);
                sdo_done(m, n, now);
            }
            break;
        case CO_PH_RUN:
        case CO_PH_LOST:
            if (n->guard.period) {
                int rtr;
                int ev = co_guard_tick(&n->guard, now, &out, &rtr);
                if (rtr)
                    push(m, &out);
                if (ev == CO_GUARD_LOST && n->phase == CO_PH_RUN) {
                    n->phase = CO_PH_LOST;
                    n->fault |= CO_F_LOST;
                    n->hb_lost++;
                    memset(n->tx, 0, sizeof n->tx);
                    logf_(m, 1, "node %u: no answer to node guarding for %u ms (guard time %u ms x life "
                          "factor %u): outputs to safe state", n->cfg.id,
                          (unsigned)n->cfg.guard_ms * n->guard.life, n->cfg.guard_ms, n->guard.life);
                }
                break;
            }
            if (n->phase == CO_PH_RUN && co_hb_tick(&n->hb, now) == CO_HB_LOST) {
                n->phase = CO_PH_LOST;
                n->fault |= CO_F_LOST;
                n->hb_lost++;
                memset(n->tx, 0, sizeof n->tx);
                logf_(m, 1, "node %u: heartbeat lost (consumer time %u ms): outputs to safe state",
                      n->cfg.id, n->cfg.hb_consumer_ms);
            }
            break;
        case CO_PH_FAILED:
            if (now >= n->retry_at)
                reset_comm(m, n, now);
            break;
        default:
            break;
        }
    }
}

void co_master_cycle(co_master *m, co_time now)
{
    (void)now;
    co_frame f;
    for (int i = 0; i < m->nnodes; i++) {
        co_node *n = &m->nodes[i];
        if (n->phase != CO_PH_RUN && n->phase != CO_PH_LOST)
            continue;
        for (unsigned k = 0; k < CO_PDO_PER_NODE; k++) {
            const co_pdo_map *map = &n->cfg.rpdo[k];
            if (!map->n)
                continue;
            memset(&f, 0, sizeof f);
            f.id = co_pdo_cobid(0, k, n->cfg.id);
            f.len = (uint8_t)((co_pdo_bits(map) + 7) / 8);
            if (n->phase == CO_PH_RUN)
                memcpy(f.data, n->tx[k], f.len);
            push(m, &f);
            n->tx_pdos++;
        }
    }
    if (co_sync_cycle(&m->sync, &f))
        push(m, &f);
}

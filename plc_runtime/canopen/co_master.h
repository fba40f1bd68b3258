/* CANopen master: the nodes it manages, their start-up (reset communication,
 * boot-up, device type check, configuration by SDO, NMT start), process data
 * exchange with SYNC, heartbeat consumer or node guarding, EMCY consumer and
 * bus faults.
 * Frame level: frames come in through co_master_rx, frames to send are taken
 * with co_master_pop; co_master_tick advances time-outs. */
#ifndef CO_MASTER_H
#define CO_MASTER_H

#include <stdarg.h>
#include "co_emcy.h"
#include "co_guard.h"
#include "co_hb.h"
#include "co_nmt.h"
#include "co_pdo.h"
#include "co_sdo.h"
#include "co_sync.h"

#define CO_MAX_WRITES 120

typedef struct co_node_cfg {
    uint8_t id;                     /* 1..127 */
    uint8_t check_type;             /* compare 0x1000 with device_type */
    uint32_t device_type;
    uint16_t hb_producer_ms;        /* written to 0x1017; 0 = leave as is */
    uint16_t hb_consumer_ms;        /* our monitoring time; 0 = off */
    uint16_t guard_ms;              /* node guarding: guard time (0x100C); 0 = off */
    uint8_t life_factor;            /* node guarding: life time factor (0x100D) */
    co_pdo_map rpdo[CO_PDO_PER_NODE], tpdo[CO_PDO_PER_NODE];
    uint8_t nextra;                 /* extra SDO writes after the PDOs (e.g. from a DCF) */
    co_sdo_write extra[64];
} co_node_cfg;

enum co_phase {
    CO_PH_IDLE, CO_PH_WAIT_BOOT, CO_PH_CHECK_TYPE, CO_PH_CONFIG, CO_PH_RUN,
    CO_PH_LOST, CO_PH_FAILED
};

/* fault bits, as the diagnostics registers show them */
enum {
    CO_F_LOST = 1 << 0,             /* heartbeat lost */
    CO_F_EMCY = 1 << 1,             /* an EMCY without a later error reset */
    CO_F_SDO = 1 << 2,              /* last SDO transfer aborted or timed out */
    CO_F_START = 1 << 3,            /* start-up failed (no answer, wrong type) */
    CO_F_TYPE = 1 << 4,             /* device type differs */
    CO_F_BOOT = 1 << 5,             /* unexpected boot-up seen (latched) */
    CO_F_SHORT = 1 << 6             /* the last TPDO was shorter than its mapping: inputs stale */
};

typedef struct co_node {
    co_node_cfg cfg;
    uint8_t phase;                  /* enum co_phase */
    uint8_t fault;                  /* CO_F_* */
    uint8_t wi, nw;                 /* configuration progress */
    co_sdo_write w[CO_MAX_WRITES];
    uint8_t wbuf[4], ubuf[8];
    co_sdo sdo;
    co_hb hb;
    co_guard guard;
    co_time deadline, retry_at;
    uint8_t rx[CO_PDO_PER_NODE][8]; /* last TPDO payloads */
    uint8_t tx[CO_PDO_PER_NODE][8]; /* RPDO payloads to send */
    uint8_t rx_new;                 /* bit per TPDO received since last take */
    uint8_t was_op;                 /* last heartbeat said operational */
    /* diagnostics */
    uint32_t device_type;           /* as read */
    uint32_t starts, unexpected_boot, hb_lost, emcy_count, sdo_errors;
    uint32_t last_abort;
    uint32_t rx_pdos, tx_pdos;
    uint32_t short_pdos;            /* TPDOs shorter than their mapping: ignored, reported */
    uint8_t short_mask;             /* bit per TPDO whose last frame was short */
    co_emcy last_emcy;
} co_node;

enum { CO_BUS_OK, CO_BUS_WARNING, CO_BUS_PASSIVE, CO_BUS_OFF, CO_BUS_DOWN };

typedef struct co_master {
    co_node *nodes;
    int nnodes;
    co_sync sync;
    co_time boot_timeout, sdo_timeout, retry_interval;
    uint8_t bus;                    /* CO_BUS_* */
    uint32_t busoff_count, err_frames, tx_dropped;
    unsigned qh, qt;
    co_frame q[2048];
    void (*log)(void *ctx, int err, const char *msg);
    void *log_ctx;
} co_master;

/* nodes[] hold their cfg; the rest is initialised here. */
void co_master_init(co_master *m, co_node *nodes, int nnodes, unsigned sync_every);
/* Begin the start-up of every node. */
void co_master_start(co_master *m, co_time now);
void co_master_rx(co_master *m, const co_frame *f, co_time now);
void co_master_tick(co_master *m, co_time now);
/* 1 when no node is still starting. */
int co_master_settled(const co_master *m);
/* Queue this cycle's RPDOs (zeros for a node not running: the safe state)
 * and, when due, the SYNC. */
void co_master_cycle(co_master *m, co_time now);
/* Next frame to send; 0 when none. */
int co_master_pop(co_master *m, co_frame *f);
/* The bus or the interface failed (state CO_BUS_*), or recovered (CO_BUS_OK). */
void co_master_bus(co_master *m, int state, const char *why);
co_node *co_master_node(co_master *m, uint8_t id);
const char *co_phase_name(int phase);

/* Start-up defaults: a node's configuration with CiA 401 PDO mappings. */
void co_node_cfg_cia401(co_node_cfg *c, uint8_t id);

#endif

/* NMT master commands (COB-ID 0x000) and the NMT states nodes report. */
#ifndef CO_NMT_H
#define CO_NMT_H

#include "co_frame.h"

enum co_nmt_cmd {
    CO_NMT_START = 0x01, CO_NMT_STOP = 0x02, CO_NMT_PREOP = 0x80,
    CO_NMT_RESET_NODE = 0x81, CO_NMT_RESET_COMM = 0x82
};

/* states in heartbeat / boot-up messages */
enum co_nmt_state {
    CO_ST_BOOTUP = 0x00, CO_ST_STOPPED = 0x04, CO_ST_OPERATIONAL = 0x05,
    CO_ST_PREOP = 0x7F, CO_ST_UNKNOWN = 0xFF
};

/* The command frame; node 0 addresses all nodes. Returns 0, or -1 for an
 * unknown command or a node id above 127 (*f untouched). */
int co_nmt_frame(co_frame *f, uint8_t cmd, uint8_t node);
const char *co_nmt_cmd_name(uint8_t cmd);
const char *co_nmt_state_name(uint8_t state);

#endif

#include <string.h>
#include "co_nmt.h"

int co_nmt_frame(co_frame *f, uint8_t cmd, uint8_t node)
{
    if (node > 127 || !strcmp(co_nmt_cmd_name(cmd), "?"))
        return -1;
    memset(f, 0, sizeof *f);
    f->id = CO_FC_NMT;
    f->len = 2;
    f->data[0] = cmd;
    f->data[1] = node;
    return 0;
}

const char *co_nmt_cmd_name(uint8_t cmd)
{
    switch (cmd) {
    case CO_NMT_START: return "start";
    case CO_NMT_STOP: return "stop";
    case CO_NMT_PREOP: return "enter pre-operational";
    case CO_NMT_RESET_NODE: return "reset node";
    case CO_NMT_RESET_COMM: return "reset communication";
    }
    return "?";
}

const char *co_nmt_state_name(uint8_t state)
{
    switch (state) {
    case CO_ST_BOOTUP: return "boot-up";
    case CO_ST_STOPPED: return "stopped";
    case CO_ST_OPERATIONAL: return "operational";
    case CO_ST_PREOP: return "pre-operational";
    }
    return "unknown";
}

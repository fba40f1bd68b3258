#include <stdio.h>
#include <string.h>
#include "co_emcy.h"

int co_emcy_decode(const co_frame *f, co_emcy *e)
{
    if (f->rtr || f->id <= CO_FC_EMCY || f->id > CO_FC_EMCY + 127 || f->len < 2)
        return -1;
    uint8_t d[8] = { 0 };
    memcpy(d, f->data, f->len > 8 ? 8 : f->len);
    e->node = (uint8_t)(f->id - CO_FC_EMCY);
    e->code = co_get16(d);
    e->reg = d[2];
    memcpy(e->msef, d + 3, 5);
    return 0;
}

const char *co_emcy_class(uint16_t code)
{
    switch (code >> 12) {
    case 0x0: return code ? "unknown" : "error reset or no error";
    case 0x1: return "generic error";
    case 0x2: return "current";
    case 0x3: return "voltage";
    case 0x4: return "temperature";
    case 0x5: return "device hardware";
    case 0x6: return "device software";
    case 0x7: return "additional modules";
    case 0x8:
        switch (code & 0xFF00) {
        case 0x8100: return "communication";
        case 0x8200: return "protocol error";
        }
        return "monitoring";
    case 0x9: return "external error";
    case 0xF: return code >> 8 == 0xFF ? "device specific" : "additional functions";
    }
    return "unknown";
}

const char *co_emcy_reg_text(uint8_t reg, char *buf, size_t len)
{
    static const char *bit[8] = { "generic", "current", "voltage", "temperature",
        "communication", "device-profile", "reserved", "manufacturer" };
    size_t n = 0;
    buf[0] = 0;
    for (int i = 0; i < 8; i++)
        if (reg & (1 << i) && n < len) {
            int w = snprintf(buf + n, len - n, "%s%s", n ? " " : "", bit[i]);
            n += w > 0 ? (size_t)w : 0;
        }
    if (!reg)
        snprintf(buf, len, "none");
    return buf;
}

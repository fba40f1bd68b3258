#include <string.h>
#include "co_sdo.h"

void co_sdo_init(co_sdo *s, uint8_t node, co_time timeout)
{
    memset(s, 0, sizeof *s);
    s->node = node;
    s->timeout = timeout;
}

static void req(co_sdo *s, co_frame *f, uint8_t cmd)
{
    memset(f, 0, sizeof *f);
    f->id = CO_FC_SDO_RX + s->node;
    f->len = 8;
    f->data[0] = cmd;
    co_put16(f->data + 1, s->index);
    f->data[3] = s->sub;
}

/* fail the transfer; if we abort it, the abort frame goes to *out */
static int fail(co_sdo *s, uint32_t code, int send, co_frame *out)
{
    s->status = CO_SDO_FAILED;
    s->abort_code = code;
    s->by_server = !send;
    if (!send)
        return 0;
    req(s, out, 0x80);
    co_put32(out->data + 4, code);
    return 1;
}

static void start(co_sdo *s, int upload, uint16_t index, uint8_t sub, co_time now)
{
    s->status = CO_SDO_BUSY;
    s->upload = (uint8_t)upload;
    s->index = index;
    s->sub = sub;
    s->toggle = 0;
    s->step = 0;
    s->len = s->size = 0;
    s->abort_code = 0;
    s->by_server = 0;
    s->deadline = now + s->timeout;
}

int co_sdo_download(co_sdo *s, uint16_t index, uint8_t sub, const void *data,
                    size_t len, co_time now, co_frame *out)
{
    if (s->status == CO_SDO_BUSY)
        return -1;
    start(s, 0, index, sub, now);
    s->buf = (uint8_t *)(uintptr_t)data;
    s->cap = len;
    if (len >= 1 && len <= 4) {          /* expedited, size indicated */
        req(s, out, (uint8_t)(0x23 | (4 - len) << 2));
        memcpy(out->data + 4, data, len);
    } else {                             /* segmented, size indicated */
        req(s, out, 0x21);
        co_put32(out->data + 4, (uint32_t)len);
    }
    return 0;
}

int co_sdo_upload(co_sdo *s, uint16_t index, uint8_t sub, void *buf, size_t cap,
                  co_time now, co_frame *out)
{
    if (s->status == CO_SDO_BUSY)
        return -1;
    start(s, 1, index, sub, now);
    s->buf = buf;
    s->cap = cap;
    req(s, out, 0x40);
    return 0;
}

static void next_segment(co_sdo *s, co_frame *out)
{
    size_t n = s->cap - s->len;
    if (n > 7)
        n = 7;
    memset(out, 0, sizeof *out);
    out->id = CO_FC_SDO_RX + s->node;
    out->len = 8;
    out->data[0] = (uint8_t)(s->toggle << 4 | (7 - n) << 1 | (s->len + n == s->cap));
    memcpy(out->data + 1, s->buf + s->len, n);
    s->len += n;
}

int co_sdo_rx(co_sdo *s, const co_frame *in, co_time now, co_frame *out)
{
    if (in->id != (uint32_t)CO_FC_SDO_TX + s->node || s->status != CO_SDO_BUSY || in->rtr)
        return 0;
    if (in->len < 8)
        return fail(s, CO_SDO_ABORT_CMD, 1, out);
    uint8_t cmd = in->data[0], scs = cmd >> 5;
    if (scs == 4) {                      /* abort from the server */
        if (co_get16(in->data + 1) != s->index || in->data[3] != s->sub)
            return 0;                    /* a stale abort of another transfer */
        return fail(s, co_get32(in->data + 4), 0, out);
    }
    s->deadline = now + s->timeout;
    int initiate = s->step == 0;
    if (initiate && (co_get16(in->data + 1) != s->index || in->data[3] != s->sub))
        return fail(s, CO_SDO_ABORT_CMD, 1, out);

    if (!s->upload) {
        if (initiate) {
            if (scs != 3)
                return fail(s, CO_SDO_ABORT_CMD, 1, out);
            if (s->cap >= 1 && s->cap <= 4) {
                s->len = s->cap;
                s->status = CO_SDO_DONE;
                return 0;
            }
            s->step = 1;
        } else {
            if (scs != 1)
                return fail(s, CO_SDO_ABORT_CMD, 1, out);
            if (((cmd >> 4) & 1) != s->toggle)
                return fail(s, CO_SDO_ABORT_TOGGLE, 1, out);
            s->toggle ^= 1;
            if (s->len == s->cap) {
                s->status = CO_SDO_DONE;
                return 0;
            }
        }
        next_segment(s, out);
        return 1;
    }

    if (initiate) {
        if (scs != 2)
            return fail(s, CO_SDO_ABORT_CMD, 1, out);
        if (cmd & 0x02) {                /* expedited */
            size_t n = (cmd & 0x01) ? 4 - ((cmd >> 2) & 3) : 4;
            if (n > s->cap)
                return fail(s, CO_SDO_ABORT_NOMEM, 1, out);
            memcpy(s->buf, in->data + 4, n);
            s->len = s->size = n;
            s->status = CO_SDO_DONE;
            return 0;
        }
        s->size = (cmd & 0x01) ? co_get32(in->data + 4) : 0;
        if (s->size > s->cap)
            return fail(s, CO_SDO_ABORT_NOMEM, 1, out);
        s->step = 1;
    } else {
        if (scs != 0)
            return fail(s, CO_SDO_ABORT_CMD, 1, out);
        if (((cmd >> 4) & 1) != s->toggle)
            return fail(s, CO_SDO_ABORT_TOGGLE, 1, out);
        size_t n = 7 - ((cmd >> 1) & 7);
        if (s->len + n > s->cap)
            return fail(s, CO_SDO_ABORT_NOMEM, 1, out);
        memcpy(s->buf + s->len, in->data + 1, n);
        s->len += n;
        s->toggle ^= 1;
        if (cmd & 0x01) {                /* last segment */
            if (s->size && s->len != s->size)
                return fail(s, CO_SDO_ABORT_LEN, 1, out);
            s->status = CO_SDO_DONE;
            return 0;
        }
    }
    req(s, out, (uint8_t)(0x60 | s->toggle << 4));
    memset(out->data + 1, 0, 7);
    return 1;
}

int co_sdo_tick(co_sdo *s, co_time now, co_frame *out)
{
    if (s->status != CO_SDO_BUSY || now < s->deadline)
        return 0;
    return fail(s, CO_SDO_ABORT_TIMEOUT, 1, out);
}

const char *co_sdo_abort_text(uint32_t code)
{
    switch (code) {
    case 0x05030000: return "toggle bit not alternated";
    case 0x05040000: return "SDO protocol timed out";
    case 0x05040001: return "client/server command specifier not valid or unknown";
    case 0x05040002: return "invalid block size";
    case 0x05040003: return "invalid sequence number";
    case 0x05040004: return "CRC error";
    case 0x05040005: return "out of memory";
    case 0x06010000: return "unsupported access to an object";
    case 0x06010001: return "attempt to read a write only object";
    case 0x06010002: return "attempt to write a read only object";
    case 0x06020000: return "object does not exist in the object dictionary";
    case 0x06040041: return "object cannot be mapped to the PDO";
    case 0x06040042: return "the number and length of the objects to be mapped would exceed PDO length";
    case 0x06040043: return "general parameter incompatibility";
    case 0x06040047: return "general internal incompatibility in the device";
    case 0x06060000: return "access failed due to a hardware error";
    case 0x06070010: return "data type does not match, length of service parameter does not match";
    case 0x06070012: return "data type does not match, length of service parameter too high";
    case 0x06070013: return "data type does not match, length of service parameter too low";
    case 0x06090011: return "sub-index does not exist";
    case 0x06090030: return "invalid value for parameter";
    case 0x06090031: return "value of parameter written too high";
    case 0x06090032: return "value of parameter written too low";
    case 0x06090036: return "maximum value is less than minimum value";
    case 0x060A0023: return "resource not available: SDO connection";
    case 0x08000000: return "general error";
    case 0x08000020: return "data cannot be transferred or stored to the application";
    case 0x08000021: return "data cannot be transferred or stored to the application because of local control";
    case 0x08000022: return "data cannot be transferred or stored to the application because of the present device state";
    case 0x08000023: return "object dictionary dynamic generation fails or no object dictionary is present";
    case 0x08000024: return "no data available";
    }
    return "unknown abort code";
}

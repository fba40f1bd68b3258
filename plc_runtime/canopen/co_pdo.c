#include <stdio.h>
#include <string.h>
#include "co_pdo.h"

uint64_t co_bits_get(const uint8_t *buf, unsigned off, unsigned len)
{
    uint64_t v = 0;
    for (unsigned i = 0; i < len; ) {
        unsigned bit = off + i, byte = bit >> 3, sh = bit & 7;
        unsigned take = 8 - sh;
        if (take > len - i)
            take = len - i;
        uint64_t part = (uint64_t)(buf[byte] >> sh) & ((1u << take) - 1);
        v |= part << i;
        i += take;
    }
    return v;
}

void co_bits_put(uint8_t *buf, unsigned off, unsigned len, uint64_t v)
{
    for (unsigned i = 0; i < len; ) {
        unsigned bit = off + i, byte = bit >> 3, sh = bit & 7;
        unsigned take = 8 - sh;
        if (take > len - i)
            take = len - i;
        unsigned mask = ((1u << take) - 1) << sh;
        unsigned part = (unsigned)((v >> i) << sh) & mask;
        buf[byte] = (uint8_t)((buf[byte] & ~mask) | part);
        i += take;
    }
}

int64_t co_bits_sext(uint64_t v, unsigned len)
{
    if (len >= 64)
        return (int64_t)v;
    uint64_t sign = (uint64_t)1 << (len - 1);
    v &= (sign << 1) - 1;
    return (int64_t)(v ^ sign) - (int64_t)sign;
}

unsigned co_pdo_offset(const co_pdo_map *m, unsigned i)
{
    unsigned off = 0;
    for (unsigned k = 0; k < i && k < m->n; k++)
        off += m->e[k].bits;
    return off;
}

unsigned co_pdo_bits(const co_pdo_map *m) { return co_pdo_offset(m, m->n); }

int co_pdo_check(const co_pdo_map *m, char *err, size_t errlen)
{
    if (m->n > CO_PDO_MAX_ENTRIES) {
        snprintf(err, errlen, "%u mapped objects, at most %d", m->n, CO_PDO_MAX_ENTRIES);
        return -1;
    }
    unsigned total = 0;
    for (unsigned i = 0; i < m->n; i++) {
        if (m->e[i].bits < 1 || m->e[i].bits > 64) {
            snprintf(err, errlen, "object 0x%04X:%02X has %u bits, must be 1..64",
                     m->e[i].index, m->e[i].sub, m->e[i].bits);
            return -1;
        }
        total += m->e[i].bits;
    }
    if (total > 64) {
        snprintf(err, errlen, "mapping holds %u bits, a PDO carries at most 64", total);
        return -1;
    }
    return 0;
}

uint32_t co_pdo_cobid(int tx, unsigned num, uint8_t node)
{
    return (tx ? CO_FC_TPDO1 : CO_FC_RPDO1) + 0x100 * num + node;
}

int co_pdo_config(int tx, unsigned num, uint8_t node, const co_pdo_map *m,
                  co_sdo_write *out, int max)
{
    uint16_t comm = (uint16_t)((tx ? 0x1800 : 0x1400) + num);
    uint16_t map = (uint16_t)((tx ? 0x1A00 : 0x1600) + num);
    uint32_t cobid = co_pdo_cobid(tx, num, node);
    int n = 0;
#define W(i, s, sz, v) do { if (n >= max) return -1; \
        out[n++] = (co_sdo_write){ (uint16_t)(i), (uint8_t)(s), (sz), (uint32_t)(v) }; } while (0)
    W(comm, 1, 4, cobid | 0x80000000u);
    if (m->n) {
        W(comm, 2, 1, m->trans);
        W(map, 0, 1, 0);
        for (unsigned i = 0; i < m->n; i++)
            W(map, i + 1, 4, (uint32_t)m->e[i].index << 16 | (uint32_t)m->e[i].sub << 8 | m->e[i].bits);
        W(map, 0, 1, m->n);
        W(comm, 1, 4, cobid);
    }
#undef W
    return n;
}

void co_pdo_cia401_default(int tx, unsigned num, co_pdo_map *m)
{
    memset(m, 0, sizeof *m);
    m->trans = 1;
    if (num == 0) {
        m->n = 8;
        for (unsigned i = 0; i < 8; i++)
            m->e[i] = (co_map_entry){ tx ? 0x6000 : 0x6200, (uint8_t)(i + 1), 8 };
    } else if (num == 1) {
        m->n = 4;
        for (unsigned i = 0; i < 4; i++)
            m->e[i] = (co_map_entry){ tx ? 0x6401 : 0x6411, (uint8_t)(i + 1), 16 };
    }
}

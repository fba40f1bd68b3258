/* Frame-level unit tests of the CANopen core. Expected frames are written
 * out by hand from CiA 301; none is taken from the code under test. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "co_emcy.h"
#include "co_guard.h"
#include "co_hb.h"
#include "co_nmt.h"
#include "co_pdo.h"
#include "co_sdo.h"
#include "co_sync.h"

static co_frame F(uint32_t id, int len, const uint8_t *d)
{
    co_frame f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.len = (uint8_t)len;
    memcpy(f.data, d, (size_t)len);
    return f;
}
#define FR(id, ...) F(id, sizeof((uint8_t[]){ __VA_ARGS__ }), (uint8_t[]){ __VA_ARGS__ })

static void frame_eq(const co_frame *a, const co_frame *b)
{
    ck_assert_uint_eq(a->id, b->id);
    ck_assert_uint_eq(a->len, b->len);
    for (int i = 0; i < a->len; i++)
        ck_assert_msg(a->data[i] == b->data[i], "byte %d: 0x%02X, expected 0x%02X",
                      i, a->data[i], b->data[i]);
}
#define EXPECT(f, id, ...) do { co_frame e_ = FR(id, __VA_ARGS__); frame_eq(&(f), &e_); } while (0)

/* ---- PDO bit fields ---------------------------------------------------- */

START_TEST(pdo_bits_by_hand)
{
    uint8_t b[8] = { 0 };
    co_bits_put(b, 6, 4, 0xF);              /* bits 6..9 */
    ck_assert_uint_eq(b[0], 0xC0);
    ck_assert_uint_eq(b[1], 0x03);
    ck_assert_uint_eq(co_bits_get(b, 6, 4), 0xF);
    memset(b, 0, 8);
    co_bits_put(b, 0, 16, 0x1234);          /* INTEGER16, little-endian */
    ck_assert_uint_eq(b[0], 0x34);
    ck_assert_uint_eq(b[1], 0x12);
    memset(b, 0, 8);
    co_bits_put(b, 16, 32, 0xDEADBEEF);     /* bytes 2..5 */
    ck_assert_uint_eq(b[2], 0xEF);
    ck_assert_uint_eq(b[5], 0xDE);
    ck_assert_uint_eq(b[1], 0);
    ck_assert_uint_eq(b[6], 0);
    memset(b, 0xFF, 8);
    co_bits_put(b, 3, 1, 0);                /* one bit cleared, the rest kept */
    ck_assert_uint_eq(b[0], 0xF7);
    ck_assert_uint_eq(b[1], 0xFF);
    memset(b, 0, 8);
    co_bits_put(b, 0, 64, 0x0102030405060708ull);
    ck_assert_uint_eq(b[0], 0x08);
    ck_assert_uint_eq(b[7], 0x01);
    ck_assert(co_bits_get(b, 0, 64) == 0x0102030405060708ull);
    memset(b, 0, 8);
    co_bits_put(b, 5, 12, 0xABC);           /* 0xABC << 5 = 0x15780 */
    ck_assert_uint_eq(b[0], 0x80);
    ck_assert_uint_eq(b[1], 0x57);
    ck_assert_uint_eq(b[2], 0x01);
    ck_assert_int_eq(co_bits_sext(0xFFF, 12), -1);
    ck_assert_int_eq(co_bits_sext(0x800, 12), -2048);
    ck_assert_int_eq(co_bits_sext(0x7FF, 12), 2047);
    ck_assert_int_eq(co_bits_sext(0x8000, 16), -32768);
    ck_assert_int_eq(co_bits_sext(1, 1), -1);
}
END_TEST

/* reference: one bit at a time, bit k of the payload = bit k%8 of byte k/8 */
static int refbit(const uint8_t *b, unsigned k) { return b[k / 8] >> (k % 8) & 1; }

START_TEST(pdo_bits_every_width_and_offset)
{
    srand(12345);
    for (unsigned len = 1; len <= 64; len++)
        for (unsigned off = 0; off + len <= 64; off++) {
            uint8_t b[8], before[8];
            for (int i = 0; i < 8; i++)
                before[i] = b[i] = (uint8_t)rand();
            uint64_t v = (uint64_t)rand() << 40 ^ (uint64_t)rand() << 20 ^ (uint64_t)rand();
            co_bits_put(b, off, len, v);
            for (unsigned k = 0; k < 64; k++) {
                int want = (k >= off && k < off + len) ? (int)(v >> (k - off) & 1) : refbit(before, k);
                ck_assert_msg(refbit(b, k) == want, "len %u off %u bit %u", len, off, k);
            }
            uint64_t mask = len == 64 ? ~0ull : ((1ull << len) - 1);
            ck_assert_msg(co_bits_get(b, off, len) == (v & mask), "get len %u off %u", len, off);
        }
}
END_TEST

START_TEST(pdo_map_check_and_config)
{
    co_pdo_map m;
    char err[128];
    co_pdo_cia401_default(0, 1, &m);        /* RPDO2: 4 x 0x6411, 16 bit */
    ck_assert_int_eq(co_pdo_check(&m, err, sizeof err), 0);
    ck_assert_uint_eq(co_pdo_bits(&m), 64);
    ck_assert_uint_eq(co_pdo_offset(&m, 3), 48);
    co_sdo_write w[32];
    int n = co_pdo_config(0, 1, 5, &m, w, 32);
    /* invalidate, type, count 0, 4 entries, count 4, validate */
    ck_assert_int_eq(n, 9);
    ck_assert_uint_eq(w[0].index, 0x1401);
    ck_assert_uint_eq(w[0].sub, 1);
    ck_assert_uint_eq(w[0].value, 0x80000305);
    ck_assert_uint_eq(w[1].index, 0x1401);
    ck_assert_uint_eq(w[1].sub, 2);
    ck_assert_uint_eq(w[1].value, 1);
    ck_assert_uint_eq(w[2].index, 0x1601);
    ck_assert_uint_eq(w[2].value, 0);
    ck_assert_uint_eq(w[3].value, 0x64110110);
    ck_assert_uint_eq(w[6].value, 0x64110410);
    ck_assert_uint_eq(w[7].index, 0x1601);
    ck_assert_uint_eq(w[7].sub, 0);
    ck_assert_uint_eq(w[7].value, 4);
    ck_assert_uint_eq(w[8].value, 0x305);
    ck_assert_uint_eq(co_pdo_cobid(1, 0, 5), 0x185);
    ck_assert_uint_eq(co_pdo_cobid(1, 3, 0x7F), 0x4FF);
    m.e[0].bits = 17;                        /* 65 bits */
    ck_assert_int_eq(co_pdo_check(&m, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "65 bits"));
    m.e[0].bits = 0;
    ck_assert_int_eq(co_pdo_check(&m, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "0x6411:01"));
    ck_assert_int_eq(co_pdo_config(0, 1, 5, &m, w, 4), -1);
    m.n = 0;                                 /* disabled PDO: only invalidated */
    ck_assert_int_eq(co_pdo_config(1, 2, 5, &m, w, 32), 1);
    ck_assert_uint_eq(w[0].index, 0x1802);
    ck_assert_uint_eq(w[0].value, 0x80000385);
}
END_TEST

/* ---- NMT and SYNC -------------------------------------------------------- */

START_TEST(nmt_frames)
{
    co_frame f;
    ck_assert_int_eq(co_nmt_frame(&f, CO_NMT_START, 5), 0);
    EXPECT(f, 0x000, 0x01, 0x05);
    ck_assert_int_eq(co_nmt_frame(&f, CO_NMT_RESET_COMM, 0), 0);
    EXPECT(f, 0x000, 0x82, 0x00);
    ck_assert_int_eq(co_nmt_frame(&f, CO_NMT_PREOP, 127), 0);
    EXPECT(f, 0x000, 0x80, 0x7F);
    ck_assert_int_eq(co_nmt_frame(&f, CO_NMT_STOP, 1), 0);
    EXPECT(f, 0x000, 0x02, 0x01);
    ck_assert_int_eq(co_nmt_frame(&f, CO_NMT_RESET_NODE, 9), 0);
    EXPECT(f, 0x000, 0x81, 0x09);
    ck_assert_int_eq(co_nmt_frame(&f, 0x03, 5), -1);
    ck_assert_int_eq(co_nmt_frame(&f, CO_NMT_START, 128), -1);
    ck_assert_str_eq(co_nmt_state_name(0x7F), "pre-operational");
    ck_assert_str_eq(co_nmt_state_name(0x05), "operational");
}
END_TEST

START_TEST(sync_every_n_cycles)
{
    co_sync s;
    co_frame f;
    int sent[7] = { 0 };
    co_sync_init(&s, 3, 0);
    for (int c = 1; c <= 6; c++)
        sent[c] = co_sync_cycle(&s, &f);
    ck_assert(sent[1] && !sent[2] && !sent[3] && sent[4] && !sent[5] && !sent[6]);
    ck_assert_uint_eq(f.id, 0x080);
    ck_assert_uint_eq(f.len, 0);
    co_sync_init(&s, 1, 3);                 /* counter 1,2,3,1 */
    int want[] = { 1, 2, 3, 1 };
    for (int c = 0; c < 4; c++) {
        ck_assert(co_sync_cycle(&s, &f));
        ck_assert_uint_eq(f.len, 1);
        ck_assert_uint_eq(f.data[0], (unsigned)want[c]);
    }
    co_sync_init(&s, 0, 0);
    ck_assert(!co_sync_cycle(&s, &f));
}
END_TEST

/* ---- SDO client ---------------------------------------------------------- */

#define T0 1000000000ull
#define TMO (500 * CO_MS)

START_TEST(sdo_expedited_upload)
{
    co_sdo s;
    co_frame out, in;
    uint8_t buf[8];
    co_sdo_init(&s, 5, TMO);
    ck_assert_int_eq(co_sdo_upload(&s, 0x1000, 0, buf, sizeof buf, T0, &out), 0);
    EXPECT(out, 0x605, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0);
    ck_assert_int_eq(co_sdo_upload(&s, 0x1000, 0, buf, sizeof buf, T0, &out), -1);
    in = FR(0x585, 0x43, 0x00, 0x10, 0x00, 0x91, 0x01, 0x0F, 0x00);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0 + CO_MS, &out), 0);
    ck_assert_int_eq(s.status, CO_SDO_DONE);
    ck_assert_uint_eq(s.len, 4);
    ck_assert_uint_eq(co_get32(buf), 0x000F0191);
    /* 2 bytes, size indicated: n = 2 */
    co_sdo_upload(&s, 0x1017, 0, buf, sizeof buf, T0, &out);
    in = FR(0x585, 0x4B, 0x17, 0x10, 0x00, 0xE8, 0x03, 0, 0);
    co_sdo_rx(&s, &in, T0, &out);
    ck_assert_int_eq(s.status, CO_SDO_DONE);
    ck_assert_uint_eq(s.len, 2);
    ck_assert_uint_eq(co_get16(buf), 1000);
}
END_TEST

START_TEST(sdo_expedited_download)
{
    co_sdo s;
    co_frame out, in;
    co_sdo_init(&s, 5, TMO);
    uint8_t v[2] = { 0x64, 0x00 };
    co_sdo_download(&s, 0x1017, 0, v, 2, T0, &out);
    EXPECT(out, 0x605, 0x2B, 0x17, 0x10, 0x00, 0x64, 0x00, 0, 0);
    in = FR(0x585, 0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 0);
    ck_assert_int_eq(s.status, CO_SDO_DONE);
    uint8_t w[4] = { 0x05, 0x02, 0x00, 0x80 };
    co_sdo_download(&s, 0x1400, 1, w, 4, T0, &out);
    EXPECT(out, 0x605, 0x23, 0x00, 0x14, 0x01, 0x05, 0x02, 0x00, 0x80);
    in = FR(0x585, 0x60, 0x00, 0x14, 0x01, 0, 0, 0, 0);
    co_sdo_rx(&s, &in, T0, &out);
    ck_assert_int_eq(s.status, CO_SDO_DONE);
    uint8_t b = 7;
    co_sdo_download(&s, 0x1600, 0, &b, 1, T0, &out);
    EXPECT(out, 0x605, 0x2F, 0x00, 0x16, 0x00, 0x07, 0, 0, 0);
    /* a response for another object is an error: the client aborts */
    in = FR(0x585, 0x60, 0x00, 0x16, 0x01, 0, 0, 0, 0);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 1);
    EXPECT(out, 0x605, 0x80, 0x00, 0x16, 0x00, 0x01, 0x00, 0x04, 0x05);
    ck_assert_int_eq(s.status, CO_SDO_FAILED);
}
END_TEST

START_TEST(sdo_segmented_upload)
{
    co_sdo s;
    co_frame out, in;
    char buf[32] = { 0 };
    co_sdo_init(&s, 5, TMO);
    co_sdo_upload(&s, 0x1008, 0, buf, sizeof buf, T0, &out);
    EXPECT(out, 0x605, 0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0);
    in = FR(0x585, 0x41, 0x08, 0x10, 0x00, 12, 0, 0, 0);     /* 12 bytes */
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 1);
    EXPECT(out, 0x605, 0x60, 0, 0, 0, 0, 0, 0, 0);
    in = FR(0x585, 0x00, 'C', 'i', 'A', '4', '0', '1', ' ');
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 1);
    EXPECT(out, 0x605, 0x70, 0, 0, 0, 0, 0, 0, 0);
    in = FR(0x585, 0x15, 's', 'l', 'a', 'v', 'e', 0, 0);      /* t=1, n=2, c=1 */
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 0);
    ck_assert_int_eq(s.status, CO_SDO_DONE);
    ck_assert_uint_eq(s.len, 12);
    ck_assert_str_eq(buf, "CiA401 slave");
}
END_TEST

START_TEST(sdo_segmented_download)
{
    co_sdo s;
    co_frame out, in;
    const char *d = "0123456789";
    co_sdo_init(&s, 5, TMO);
    co_sdo_download(&s, 0x2000, 3, d, 10, T0, &out);
    EXPECT(out, 0x605, 0x21, 0x00, 0x20, 0x03, 10, 0, 0, 0);
    in = FR(0x585, 0x60, 0x00, 0x20, 0x03, 0, 0, 0, 0);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 1);
    EXPECT(out, 0x605, 0x00, '0', '1', '2', '3', '4', '5', '6');
    in = FR(0x585, 0x20, 0, 0, 0, 0, 0, 0, 0);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 1);
    EXPECT(out, 0x605, 0x19, '7', '8', '9', 0, 0, 0, 0);      /* t=1, n=4, c=1 */
    in = FR(0x585, 0x30, 0, 0, 0, 0, 0, 0, 0);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 0);
    ck_assert_int_eq(s.status, CO_SDO_DONE);
    /* exactly 7 bytes: one full last segment, n=0, c=1 */
    co_sdo_download(&s, 0x2000, 4, d, 7, T0, &out);
    EXPECT(out, 0x605, 0x21, 0x00, 0x20, 0x04, 7, 0, 0, 0);
    in = FR(0x585, 0x60, 0x00, 0x20, 0x04, 0, 0, 0, 0);
    co_sdo_rx(&s, &in, T0, &out);
    EXPECT(out, 0x605, 0x01, '0', '1', '2', '3', '4', '5', '6');
}
END_TEST

START_TEST(sdo_toggle_error_aborts)
{
    co_sdo s;
    co_frame out, in;
    char buf[32];
    co_sdo_init(&s, 5, TMO);
    co_sdo_upload(&s, 0x1008, 0, buf, sizeof buf, T0, &out);
    in = FR(0x585, 0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0);
    co_sdo_rx(&s, &in, T0, &out);
    in = FR(0x585, 0x10, 'x', 'x', 'x', 'x', 'x', 'x', 'x');  /* toggle 1, expected 0 */
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 1);
    EXPECT(out, 0x605, 0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x03, 0x05);
    ck_assert_int_eq(s.status, CO_SDO_FAILED);
    ck_assert_uint_eq(s.abort_code, 0x05030000);
    ck_assert_str_eq(co_sdo_abort_text(s.abort_code), "toggle bit not alternated");
    /* more data than the buffer holds: out of memory */
    co_sdo_upload(&s, 0x1008, 0, buf, 4, T0, &out);
    in = FR(0x585, 0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 1);
    EXPECT(out, 0x605, 0x80, 0x08, 0x10, 0x00, 0x05, 0x00, 0x04, 0x05);
}
END_TEST

START_TEST(sdo_server_abort)
{
    co_sdo s;
    co_frame out, in;
    uint8_t buf[4];
    co_sdo_init(&s, 5, TMO);
    co_sdo_upload(&s, 0x6401, 9, buf, sizeof buf, T0, &out);
    /* an abort for another object is not ours */
    in = FR(0x585, 0x80, 0x00, 0x10, 0x00, 0x00, 0x00, 0x02, 0x06);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 0);
    ck_assert_int_eq(s.status, CO_SDO_BUSY);
    in = FR(0x585, 0x80, 0x01, 0x64, 0x09, 0x11, 0x00, 0x09, 0x06);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 0);    /* nothing sent back */
    ck_assert_int_eq(s.status, CO_SDO_FAILED);
    ck_assert_int_eq(s.by_server, 1);
    ck_assert_uint_eq(s.abort_code, 0x06090011);
    ck_assert_str_eq(co_sdo_abort_text(0x06090011), "sub-index does not exist");
    ck_assert_str_eq(co_sdo_abort_text(0x06020000), "object does not exist in the object dictionary");
    ck_assert_str_eq(co_sdo_abort_text(0x06010002), "attempt to write a read only object");
    ck_assert_str_eq(co_sdo_abort_text(0x12345678), "unknown abort code");
    /* frames of another node are ignored */
    co_sdo_upload(&s, 0x1000, 0, buf, sizeof buf, T0, &out);
    in = FR(0x586, 0x43, 0x00, 0x10, 0x00, 1, 2, 3, 4);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0, &out), 0);
    ck_assert_int_eq(s.status, CO_SDO_BUSY);
}
END_TEST

START_TEST(sdo_timeout)
{
    co_sdo s;
    co_frame out, in;
    uint8_t buf[32];
    co_sdo_init(&s, 5, TMO);
    co_sdo_upload(&s, 0x1000, 0, buf, sizeof buf, T0, &out);
    ck_assert_int_eq(co_sdo_tick(&s, T0 + TMO - 1, &out), 0);
    ck_assert_int_eq(s.status, CO_SDO_BUSY);
    ck_assert_int_eq(co_sdo_tick(&s, T0 + TMO, &out), 1);
    EXPECT(out, 0x605, 0x80, 0x00, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05);
    ck_assert_int_eq(s.status, CO_SDO_FAILED);
    ck_assert_uint_eq(s.abort_code, CO_SDO_ABORT_TIMEOUT);
    ck_assert_str_eq(co_sdo_abort_text(s.abort_code), "SDO protocol timed out");
    /* the timeout runs per exchange: each answer restarts it */
    co_sdo_upload(&s, 0x1008, 0, buf, sizeof buf, T0, &out);
    in = FR(0x585, 0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0);
    co_sdo_rx(&s, &in, T0 + 400 * CO_MS, &out);
    ck_assert_int_eq(co_sdo_tick(&s, T0 + 800 * CO_MS, &out), 0);
    ck_assert_int_eq(co_sdo_tick(&s, T0 + 900 * CO_MS, &out), 1);
    EXPECT(out, 0x605, 0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05);
    /* a late answer after the timeout changes nothing */
    in = FR(0x585, 0x00, 1, 2, 3, 4, 5, 6, 7);
    ck_assert_int_eq(co_sdo_rx(&s, &in, T0 + 950 * CO_MS, &out), 0);
    ck_assert_int_eq(s.status, CO_SDO_FAILED);
}
END_TEST

/* ---- heartbeat consumer -------------------------------------------------- */

START_TEST(hb_states_and_timing)
{
    co_hb h;
    co_frame f;
    co_hb_init(&h, 7, 250 * CO_MS);
    ck_assert_int_eq(co_hb_tick(&h, T0 + 10000 * CO_MS), CO_HB_NONE);   /* not yet heard */
    f = FR(0x707, 0x00);
    ck_assert_int_eq(co_hb_rx(&h, &f, T0), CO_HB_BOOTUP);
    ck_assert_uint_eq(h.bootups, 1);
    f = FR(0x707, 0x7F);
    ck_assert_int_eq(co_hb_rx(&h, &f, T0 + 100 * CO_MS), CO_HB_STATE);
    ck_assert_uint_eq(h.state, 0x7F);
    ck_assert_int_eq(co_hb_rx(&h, &f, T0 + 200 * CO_MS), CO_HB_NONE);   /* same state */
    f = FR(0x707, 0x05);
    ck_assert_int_eq(co_hb_rx(&h, &f, T0 + 300 * CO_MS), CO_HB_STATE);
    f = FR(0x707, 0x04);
    ck_assert_int_eq(co_hb_rx(&h, &f, T0 + 400 * CO_MS), CO_HB_STATE);
    ck_assert_str_eq(co_nmt_state_name(h.state), "stopped");
    /* last heard at 400 ms: lost after 650 ms, not at 650 ms exactly */
    ck_assert_int_eq(co_hb_tick(&h, T0 + 650 * CO_MS), CO_HB_NONE);
    ck_assert_int_eq(co_hb_tick(&h, T0 + 651 * CO_MS), CO_HB_LOST);
    ck_assert_int_eq(co_hb_tick(&h, T0 + 900 * CO_MS), CO_HB_NONE);     /* reported once */
    ck_assert_uint_eq(h.losses, 1);
    f = FR(0x707, 0x05);
    ck_assert_int_eq(co_hb_rx(&h, &f, T0 + 1000 * CO_MS), CO_HB_BACK);
    ck_assert_int_eq(co_hb_tick(&h, T0 + 1200 * CO_MS), CO_HB_NONE);
    f = FR(0x708, 0x05);                                              /* another node */
    ck_assert_int_eq(co_hb_rx(&h, &f, T0 + 1300 * CO_MS), CO_HB_NONE);
    ck_assert_int_eq(co_hb_tick(&h, T0 + 1251 * CO_MS), CO_HB_LOST);
    co_hb_init(&h, 7, 0);                                             /* not monitored */
    co_hb_rx(&h, &f, T0);
    ck_assert_int_eq(co_hb_tick(&h, T0 + 100000 * CO_MS), CO_HB_NONE);
}
END_TEST

/* ---- node guarding (CiA 301 7.2.8.3.2.1) --------------------------------- */

START_TEST(guard_rtr_toggle_and_life_time)
{
    co_guard g;
    co_frame f, r;
    int rtr;
    co_guard_init(&g, 9, 100 * CO_MS, 3);
    ck_assert_int_eq(co_guard_tick(&g, T0, &r, &rtr), CO_GUARD_NONE);
    ck_assert_int_eq(rtr, 0);                                 /* not started */
    co_guard_start(&g, T0);
    co_guard_tick(&g, T0, &r, &rtr);
    ck_assert_int_eq(rtr, 1);                                 /* RTR on 0x709 at once */
    ck_assert_uint_eq(r.id, 0x709);
    ck_assert_uint_eq(r.rtr, 1);
    co_guard_tick(&g, T0 + 99 * CO_MS, &r, &rtr);
    ck_assert_int_eq(rtr, 0);
    co_guard_tick(&g, T0 + 100 * CO_MS, &r, &rtr);           /* every guard time */
    ck_assert_int_eq(rtr, 1);
    f = FR(0x709, 0x05);                                      /* operational, toggle 0 */
    ck_assert_int_eq(co_guard_rx(&g, &f, T0 + 101 * CO_MS), CO_GUARD_STATE);
    ck_assert_int_eq(co_guard_rx(&g, &f, T0 + 102 * CO_MS), CO_GUARD_TOGGLE);   /* toggle 0 again */
    ck_assert_uint_eq(g.toggle_errors, 1);
    f = FR(0x709, 0x85);                                      /* toggle 1: good */
    ck_assert_int_eq(co_guard_rx(&g, &f, T0 + 200 * CO_MS), CO_GUARD_NONE);
    f = FR(0x709, 0x00);                                      /* a boot-up is no answer */
    ck_assert_int_eq(co_guard_rx(&g, &f, T0 + 210 * CO_MS), CO_GUARD_NONE);
    f = FR(0x70A, 0x05);                                      /* another node */
    ck_assert_int_eq(co_guard_rx(&g, &f, T0 + 220 * CO_MS), CO_GUARD_NONE);
    /* last good answer at 200 ms: lost after 100 x 3 = 300 ms, not at 300 exactly */
    ck_assert_int_eq(co_guard_tick(&g, T0 + 500 * CO_MS, &r, &rtr), CO_GUARD_NONE);
    ck_assert_int_eq(co_guard_tick(&g, T0 + 501 * CO_MS, &r, &rtr), CO_GUARD_LOST);
    ck_assert_int_eq(co_guard_tick(&g, T0 + 600 * CO_MS, &r, &rtr), CO_GUARD_NONE);   /* once */
    ck_assert_int_eq(rtr, 1);                                 /* RTRs go on while lost */
    ck_assert_uint_eq(g.losses, 1);
    f = FR(0x709, 0x05);                                      /* toggle 0 expected now */
    ck_assert_int_eq(co_guard_rx(&g, &f, T0 + 650 * CO_MS), CO_GUARD_BACK);
    /* a late tick gives one RTR, not a burst */
    int n = 0;
    co_guard_tick(&g, T0 + 2000 * CO_MS, &r, &rtr);
    n += rtr;
    co_guard_tick(&g, T0 + 2001 * CO_MS, &r, &rtr);
    n += rtr;
    ck_assert_int_eq(n, 1);
}
END_TEST

/* ---- EMCY ---------------------------------------------------------------- */

START_TEST(emcy_decode)
{
    co_emcy e;
    char reg[96];
    co_frame f = FR(0x083, 0x10, 0x32, 0x05, 0x01, 0x02, 0x03, 0x04, 0x05);
    ck_assert_int_eq(co_emcy_decode(&f, &e), 0);
    ck_assert_uint_eq(e.node, 3);
    ck_assert_uint_eq(e.code, 0x3210);
    ck_assert_uint_eq(e.reg, 0x05);
    ck_assert_uint_eq(e.msef[0], 1);
    ck_assert_uint_eq(e.msef[4], 5);
    ck_assert_str_eq(co_emcy_class(e.code), "voltage");
    ck_assert_str_eq(co_emcy_reg_text(e.reg, reg, sizeof reg), "generic voltage");
    f = FR(0x0FF, 0x30, 0x81, 0x11, 0, 0, 0, 0, 0);
    ck_assert_int_eq(co_emcy_decode(&f, &e), 0);
    ck_assert_uint_eq(e.node, 127);
    ck_assert_uint_eq(e.code, 0x8130);
    ck_assert_str_eq(co_emcy_class(e.code), "communication");
    ck_assert_str_eq(co_emcy_reg_text(e.reg, reg, sizeof reg), "generic communication");
    f = FR(0x081, 0x00, 0x00, 0x00, 0, 0, 0, 0, 0);
    ck_assert_int_eq(co_emcy_decode(&f, &e), 0);
    ck_assert_str_eq(co_emcy_class(e.code), "error reset or no error");
    f = F(0x080, 0, (uint8_t[]){ 0 });                 /* SYNC, not EMCY */
    ck_assert_int_eq(co_emcy_decode(&f, &e), -1);
    f = FR(0x100, 1, 2, 3);
    ck_assert_int_eq(co_emcy_decode(&f, &e), -1);
    f = FR(0x085, 0x00);                                /* too short */
    ck_assert_int_eq(co_emcy_decode(&f, &e), -1);
    ck_assert_str_eq(co_emcy_class(0x4210), "temperature");
    ck_assert_str_eq(co_emcy_class(0x2310), "current");
}
END_TEST

Suite *core_suite(void)
{
    Suite *s = suite_create("canopen_core");
    TCase *t = tcase_create("core");
    tcase_add_test(t, pdo_bits_by_hand);
    tcase_add_test(t, pdo_bits_every_width_and_offset);
    tcase_add_test(t, pdo_map_check_and_config);
    tcase_add_test(t, nmt_frames);
    tcase_add_test(t, sync_every_n_cycles);
    tcase_add_test(t, sdo_expedited_upload);
    tcase_add_test(t, sdo_expedited_download);
    tcase_add_test(t, sdo_segmented_upload);
    tcase_add_test(t, sdo_segmented_download);
    tcase_add_test(t, sdo_toggle_error_aborts);
    tcase_add_test(t, sdo_server_abort);
    tcase_add_test(t, sdo_timeout);
    tcase_add_test(t, hb_states_and_timing);
    tcase_add_test(t, guard_rtr_toggle_and_life_time);
    tcase_add_test(t, emcy_decode);
    suite_add_tcase(s, t);
    return s;
}

/* eds: a node's configuration from its EDS or DCF file (CiA 306), as
 * drive vendors ship them.  What is taken (ParameterValue where the file
 * has one, a DCF; DefaultValue otherwise, an EDS):
 *   0x1000           the device type, checked at start-up
 *   0x1400..0x1403,  RPDO/TPDO 1..4: COB-ID (bit 31 = not used; only the
 *   0x1800..0x1803   predefined 0x200/0x180 + 0x100 k + node id are taken)
 *   0x1600..0x1603,  their mappings (sub 0 the count, subs 1.. the entries
 *   0x1A00..0x1A03   index << 16 | sub << 8 | bits)
 *   every other object with a ParameterValue, writable (rw, wo, rww,
 *   rwr) and of up to 32 bits: an SDO write at start-up, in file order
 *   (0x1017, 0x100C and 0x100D excepted: the configuration's heartbeat and
 *   guarding keys own them).
 * "$NODEID+x" (or "x+$NODEID") values take the node's id.  The file is read
 * with libinih; any problem is one message naming the file, the line where
 * it is known, the object and the fix. */
#ifndef EDS_H
#define EDS_H

#include <stddef.h>
#include "co_master.h"

#define EDS_MAX_WRITES 64

typedef struct eds_info {
    uint32_t device_type;
    int has_device_type;
    co_pdo_map rpdo[CO_PDO_PER_NODE], tpdo[CO_PDO_PER_NODE];
    int has_pdo;                    /* some PDO object was in the file */
    int nwrites;
    co_sdo_write w[EDS_MAX_WRITES];
} eds_info;

/* Read path for node id; 0, or -1 with a message in err. */
int eds_load(const char *path, uint8_t node, eds_info *out, char *err, size_t n);

#endif

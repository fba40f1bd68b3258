/*
** tags.h: the tag list of a running configuration, for HMIs and SCADA:
** every program variable a Modbus client can reach, with its table,
** address, register count, IEC type, word order and access, as CSV
** (TAGS.csv) and JSON (TAGS.json), written beside VARIABLES.csv by
** `plcrt --tags DIR` (plcrt-build does it at its CHECK step).
**
** The one idea: the list is read off what plcrt will serve, not off the
** source: a located variable is a tag when its address in the process
** image lies in the fixed Modbus map (docs/modbus.md: %IX, %QX, %IW, %QW,
** %MW, %MD, %ML; the others are not served), a symbol of [modbus.symbols]
** as the Modbus map resolved it. Word order as the server sends values:
** "high word first" for several registers, "low byte" for an 8-bit type in
** a register (the high byte 0: a SINT -100 reads 156), else empty.
*/
#ifndef TAGS_H
#define TAGS_H

#include <stddef.h>
#include "mbmap.h"
#include "program.h"

/* Call after the program's init (located addresses bound) and mb_new; mb
** NULL (Modbus off) gives empty lists. 0, or -1 with a message in err. */
int tags_write(const plc_program *p, const mb_shared *mb, const char *dir, char *err, size_t n);

#endif

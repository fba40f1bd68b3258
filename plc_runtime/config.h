/*
** config.h: the INI configuration (libinih). Every key, its default and
** meaning are documented in docs/config.md. Sections that belong to an I/O
** backend ([sim], [sim.axis0], [canopen...]) are handed to that backend
** when `[io] backend` lists it; sections of other known backends are
** ignored, so switching backend is one key; anything else is an error.
**
** The file is checked whole, in three steps that all name file, line,
** section and key: config_load (syntax, every value; host names in
** [modbus] bind resolved to an IPv4 address), then the program's checks in
** main.c (status_vars, the symbol map), then config_check_host (what only
** this machine can tell: the bind address, the CPU, the retain folder).
*/
#ifndef PLC_CONFIG_H
#define PLC_CONFIG_H

#include <stddef.h>
#include "io_backend.h"

#define CFG_MAX_SYMBOLS 256
#define CFG_MAX_STATUS 8
#define CFG_MAX_LINE 2048       /* characters in one line, newline excluded */
#define CFG_MAX_FILE (1 << 20)  /* bytes in one file */
#define CFG_NKEYS 24            /* keys of the runtime's own sections */

enum { MB_COILS, MB_DISCRETE, MB_INPUT, MB_HOLDING };

typedef struct cfg_symbol {
    char path[160];
    int table;          /* MB_COILS .. MB_HOLDING */
    unsigned addr;
    int writable;
    int line;           /* where it was declared, for later messages */
} cfg_symbol;

typedef struct plc_config {
    char file[256];
    /* [plc] */
    int log_level;
    int status_interval;                /* s, 0 = no status line */
    char status_vars[CFG_MAX_STATUS][160];
    int nstatus;
    /* [scan] */
    int priority;                       /* SCHED_FIFO priority, 0 = normal */
    int cpu;                            /* -1 = any */
    int lock_memory;
    int overrun_log_interval;           /* s */
    int watchdog_ms;                    /* one cycle's program at most; 0 = off */
    /* [io] */
    char backend[128];                  /* "sim" or "sim, modbus_io" */
    const io_backend_ops *io;           /* io_multi, over the listed ones */
    void *io_state;                     /* created during parsing */
    char io_list[128];                  /* the backends io_state holds */
    /* [modbus] */
    int mb_enabled;
    char mb_bind[64];                   /* dotted IPv4 (host names resolved) */
    char mb_bind_name[256];             /* as given, if a host name; "" otherwise */
    int mb_port;
    int mb_max_clients;
    int mb_idle_timeout;                /* s, 0 = never */
    /* [modbus_rtu]: the same map on a serial line */
    char rtu_device[128];               /* "" = none */
    int rtu_baud, rtu_data_bits, rtu_stop_bits, rtu_slave;
    char rtu_parity;                    /* 'N', 'E', 'O' */
    cfg_symbol symbols[CFG_MAX_SYMBOLS];
    int nsymbols;
    /* [retain] */
    char retain_file[256];              /* "" = no retain */
    int retain_period;                  /* s, 0 = only at shutdown */
    /* [trace] */
    int trace_samples;                  /* per channel and buffer */
    /* [debug] */
    int allow_force;
    int key_line[CFG_NKEYS];            /* where each key was given, 0 = default */
} plc_config;

/* Defaults, with backend `sim` created. */
int config_defaults(plc_config *c, char *err, size_t errlen);
/* Read path over the defaults. 0, or -1 with "FILE:LINE: ..." in err. */
int config_load(plc_config *c, const char *path, char *err, size_t errlen);
/* Read INI text (for tests); name is used in messages. */
int config_load_string(plc_config *c, const char *name, const char *text,
                       char *err, size_t errlen);
/* Line where [section] key was given; 0 if it has its default (or is not
** one of the runtime's own keys). */
int config_line(const plc_config *c, const char *section, const char *key);
/* A message about [section] key in the configuration's words:
** "FILE:LINE: [section] key: ..." or, for a default value,
** "FILE: [section] key (default): ...". */
void config_msg(const plc_config *c, const char *section, const char *key,
                char *out, size_t n, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));
/* What only this host can tell, for --check-config and the start alike:
** the Modbus bind address is one of this host's (if Modbus is enabled) and
** the port may be bound by this user; the scan's CPU exists; the retain
** file's folder exists and is writable (when the file is given or the
** program has retained variables: nretained). 0, or -1 with the message. */
int config_check_host(const plc_config *c, size_t nretained, char *err, size_t errlen);
/* Free the backend state if the backend was never opened. */
void config_free(plc_config *c);

#endif

/* log.h: messages on stderr, "plcrt: level: text". Not for the scan thread
** (it counts; the housekeeping thread reports). */
#ifndef PLC_LOG_H
#define PLC_LOG_H

enum { LOG_ERROR, LOG_WARN, LOG_INFO, LOG_DEBUG };

void plc_log_level(int level);
int plc_log_parse_level(const char *s);   /* -1 if unknown */
void plc_log(int level, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

#endif

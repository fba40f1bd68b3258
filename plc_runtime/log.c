/* log.c */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "log.h"

static int max_level = LOG_INFO;
static const char *names[] = { "error", "warning", "info", "debug" };

void plc_log_level(int level) { max_level = level; }

int plc_log_parse_level(const char *s)
{
    for (int i = 0; i < 4; i++)
        if (!strcmp(s, names[i])) return i;
    if (!strcmp(s, "warn")) return LOG_WARN;
    return -1;
}

void plc_log(int level, const char *fmt, ...)
{
    if (level > max_level) return;
    char buf[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    fprintf(stderr, "plcrt: %s: %s\n", names[level], buf);
}

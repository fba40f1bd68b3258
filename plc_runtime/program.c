/* program.c: look-ups in the linked program's variable table. */
#include <strings.h>
#include "program.h"

const plc_var *plc_var_find(const plc_program *p, const char *path)
{
    for (size_t i = 0; i < p->nvars; i++)
        if (!strcasecmp(p->vars[i].path, path)) return &p->vars[i];
    return NULL;
}

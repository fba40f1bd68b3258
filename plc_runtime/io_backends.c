/* io_backends.c: the list of I/O backends (add new ones here) and what
** they share. */
#include <stdio.h>
#include <string.h>
#include "io_backend.h"

extern const io_backend_ops io_none, io_sim, io_canopen, io_modbus;

const io_backend_ops *const io_backends[] = { &io_none, &io_sim, &io_canopen, &io_modbus, NULL };

const io_backend_ops *io_backend_find(const char *name)
{
    for (int i = 0; io_backends[i]; i++)
        if (!strcmp(io_backends[i]->name, name)) return io_backends[i];
    return NULL;
}

int io_inputs_apart(const io_input_use *in, int n, char *err, size_t errlen)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < i; j++)
            if (in[i].p < in[j].p + in[j].w && in[j].p < in[i].p + in[i].w) {
                snprintf(err, errlen, "%s and %s write the same input: give each its own address",
                         in[j].who, in[i].who);
                return -1;
            }
    return 0;
}

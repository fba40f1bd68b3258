/* io_backends.c: the list of I/O backends. Add new ones here. */
#include <string.h>
#include "io_backend.h"

extern const io_backend_ops io_none, io_sim, io_canopen;

const io_backend_ops *const io_backends[] = { &io_none, &io_sim, &io_canopen, NULL };

const io_backend_ops *io_backend_find(const char *name)
{
    for (int i = 0; io_backends[i]; i++)
        if (!strcmp(io_backends[i]->name, name)) return io_backends[i];
    return NULL;
}

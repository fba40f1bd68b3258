/*
** retain.h: the retain file. A file holds one generation of the retained
** variables: magic, generation number, then per variable its IEC path,
** type name and bytes, then a CRC-32 of all that. Saving writes FILE.tmp,
** fsyncs it, keeps the current FILE as FILE.prev (a hard link) and renames
** FILE.tmp over FILE, then fsyncs the folder: at every instant FILE is a
** complete generation (or absent before the first save). Loading takes FILE
** if it is intact, else FILE.prev, else nothing; a damaged file is
** reported and never loaded, not even in part.
*/
#ifndef RETAIN_H
#define RETAIN_H

#include <stddef.h>
#include <stdint.h>

typedef struct retain_var {
    const char *path, *type;
    void *data;          /* the copy to save / to load into */
    size_t size;
} retain_var;

/* Save one generation. 0, or -1 with a message in err. */
int retain_save(const char *file, const retain_var *v, size_t n, uint64_t gen,
                char *err, size_t errlen);

/* Load one file into v[] (variables whose path, type and size match; the
** others keep their data). 0 loaded, 1 no such file, -1 damaged (message
** in err; v[] untouched), 2 intact but none of its values belongs to a
** variable of v[] (another program's file; message in err; v[]
** untouched). *gen gets the generation. */
int retain_load_file(const char *file, retain_var *v, size_t n, uint64_t *gen,
                     char *err, size_t errlen);

/* FILE, else FILE.prev. Reports through plc_log. 0 loaded (gen set),
** 1 nothing usable (v[] untouched). A damaged file is moved to FILE.bad,
** another program's to FILE.foreign (or .prev.foreign), out of the way of
** the saves that follow. */
int retain_load(const char *file, retain_var *v, size_t n, uint64_t *gen);

uint32_t retain_crc32(const void *p, size_t n);

#endif

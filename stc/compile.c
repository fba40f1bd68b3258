/* One compilation, from source text to C files; fatal errors return here.
** Several input files make one program, as if concatenated in order: each is
** lexed and parsed on its own (so every diagnostic names the file and line
** the user wrote), then all declarations are checked together. */
#include "stc.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

int stc_compile_lib(const Source *srcs, int nsrcs, int nlib, const char *outdir) {
    static Source lib = {"<standard library>", stdlib_st, 0};
    lib.len = strlen(stdlib_st);
    jmp_buf jb;
    error_count = 0;
    stc_error_jmp = &jb;
    if (setjmp(jb)) { stc_error_jmp = NULL; xfree_all(); return 1; }
    Unit u = {0};
    parse_unit(&u, &lib, true);
    /* a file with nothing in it (comments only, or empty) is accepted, as
    ** matiec does */
    for (int i = 0; i < nsrcs; i++) {
        u.library = i < nlib;
        parse_unit(&u, &srcs[i], false);
    }
    u.library = false;
    replace_library(&u);
    sema(&u);
    int rc = 1;
    if (!error_count) {
        struct stat st;
        if (outdir && stat(outdir, &st) != 0 && mkdir(outdir, 0777) != 0)
            fprintf(stderr, "stc: cannot create '%s': %s\n", outdir, strerror(errno));
        else
            rc = codegen(&u, outdir) ? 1 : 0;
    }
    stc_error_jmp = NULL;
    xfree_all();
    return rc;
}

int stc_compile_files(const Source *srcs, int nsrcs, const char *outdir) {
    return stc_compile_lib(srcs, nsrcs, 0, outdir);
}

int stc_compile(const Source *src, const char *outdir) {
    return stc_compile_files(src, 1, outdir);
}

/* One compilation, from source text to C files; fatal errors return here. */
#include "stc.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

int stc_compile(const Source *src, const char *outdir) {
    static Source lib = {"<standard library>", stdlib_st, 0};
    lib.len = strlen(stdlib_st);
    jmp_buf jb;
    error_count = 0;
    stc_error_jmp = &jb;
    if (setjmp(jb)) { stc_error_jmp = NULL; xfree_all(); return 1; }
    Unit u = {0};
    parse_unit(&u, &lib, true);
    int nlib = u.pous.n;
    parse_unit(&u, src, false);
    if (u.pous.n == nlib && !u.types.n && !u.configs.n) {
        Loc at = {src, 1, 1};
        fatal_at(at, "nothing to compile: no FUNCTION, FUNCTION_BLOCK, PROGRAM, TYPE or CONFIGURATION");
    }
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

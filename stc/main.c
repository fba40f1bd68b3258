/* stc command line: stc [-I libdir] [-T outdir] [-L lib.st]... file.st...,
** like matiec's iec2c (which takes one file; several make one program, as if
** concatenated); -L names the project's library, which the files' own
** declarations replace; --join writes one file in declaration order. */
#include "stc.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef STC_INCLUDE_DIR
#define STC_INCLUDE_DIR "/usr/local/share/stc/include"
#endif

static void usage(FILE *f) {
    fputs("usage: stc [-I libdir] [-T outdir] [-L lib.st]... file.st...\n"
          "       stc --join out.st [--map out.map] [-L lib.st]... file.st...\n"
          "       stc --version | --include-dir | --help\n"
          "Compiles IEC 61131-3 Structured Text to C, in matiec's file layout:\n"
          "POUS.c, POUS.h, <Config>.c/.h, <Resource>.c, LOCATED_VARIABLES.h and\n"
          "VARIABLES.csv in outdir (default: the current directory). Several files\n"
          "make one program, as if concatenated in the order given: what one\n"
          "declares, the others use.\n"
          "Build the output with: cc -I \"$(stc --include-dir)\" -c <Config>.c <Resource>.c\n"
          "  -I libdir  accepted for iec2c compatibility; the standard library is built in\n"
          "  -T outdir  where to write the C files (created if missing)\n"
          "  -L lib.st  a file of the project's library: a FUNCTION, FUNCTION_BLOCK,\n"
          "             PROGRAM or type that file.st declares too replaces the library's\n"
          "             (a warning when the two differ)\n"
          "  --join out.st  compile nothing: write the declarations of the files as one\n"
          "             file in which each comes before its first use (for iec2c, which\n"
          "             reads one file in order); --map: which lines came from where,\n"
          "             one \"FIRST LAST FROM FILE\" line per declaration\n", f);
}

static char *read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) { fprintf(stderr, "stc: cannot open '%s': %s\n", path, strerror(errno)); exit(1); }
    Buf b = {0};
    buf_put(&b, "");
    char chunk[65536];
    size_t n;
    while ((n = fread(chunk, 1, sizeof chunk, f)) > 0) {
        if (b.n + n > 64u * 1024 * 1024) { fprintf(stderr, "stc: '%s' is too large\n", path); exit(1); }
        char tmp[2] = {0, 0};
        for (size_t i = 0; i < n; i++) {   /* keep NUL bytes: the lexer reports them */
            tmp[0] = chunk[i];
            if (chunk[i]) buf_put(&b, tmp);
            else { buf_put(&b, " "); b.s[b.n - 1] = 0; }
        }
    }
    if (ferror(f)) { fprintf(stderr, "stc: cannot read '%s': %s\n", path, strerror(errno)); exit(1); }
    fclose(f);
    *len = b.n;
    return b.s;
}

int main(int argc, char **argv) {
    const char *outdir = ".", *join = NULL, *map = NULL;
    int ninputs = 0, nlib = 0;
    Source *inputs = calloc((size_t)argc, sizeof *inputs);
    Source *libs = calloc((size_t)argc, sizeof *libs);
    if (!inputs || !libs) { fputs("stc: out of memory\n", stderr); return 1; }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--version")) { printf("stc %s\n", STC_VERSION); return 0; }
        if (!strcmp(a, "--include-dir")) { printf("%s\n", STC_INCLUDE_DIR); return 0; }
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { usage(stdout); return 0; }
        if (!strcmp(a, "-L") || !strcmp(a, "--join") || !strcmp(a, "--map")) {
            if (i + 1 >= argc) { fprintf(stderr, "stc: %s needs a file\n", a); return 1; }
            if (a[1] == 'L') libs[nlib++].name = argv[i + 1];
            else if (a[2] == 'j') join = argv[i + 1];
            else map = argv[i + 1];
            i++;
            continue;
        }
        if (!strcmp(a, "-T") || !strcmp(a, "-I")) {
            if (i + 1 >= argc) { fprintf(stderr, "stc: %s needs a folder\n", a); return 1; }
            if (a[1] == 'T') outdir = argv[i + 1];
            i++;
            continue;
        }
        if (!strncmp(a, "-T", 2)) { outdir = a + 2; continue; }
        if (!strncmp(a, "-I", 2)) continue;
        if (a[0] == '-' && a[1]) { fprintf(stderr, "stc: unknown option '%s'\n", a); usage(stderr); return 1; }
        inputs[ninputs++].name = a;
    }
    if (!ninputs) { usage(stderr); return 1; }

    /* one list: the library's files first */
    Source *all = calloc((size_t)(nlib + ninputs), sizeof *all);
    if (!all) { fputs("stc: out of memory\n", stderr); return 1; }
    memcpy(all, libs, sizeof *all * (size_t)nlib);
    memcpy(all + nlib, inputs, sizeof *all * (size_t)ninputs);
    for (int i = 0; i < nlib + ninputs; i++) all[i].text = read_file(all[i].name, &all[i].len);
    int rc = join ? stc_join_files(all, nlib + ninputs, nlib, join, map)
                  : stc_compile_lib(all, nlib + ninputs, nlib, outdir);
    free(all);
    free(libs);
    free(inputs);
    return rc;
}

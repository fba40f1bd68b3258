/* libFuzzer target: any input must give C output or diagnostics, never a
** crash, a hang or a sanitizer report. Nothing is written to disk. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../stc/stc.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char *text = malloc(size + 1);
    if (!text) return 0;
    memcpy(text, data, size);
    text[size] = 0;
    Source s = {"fuzz.st", text, size};
    FILE *saved = stderr;
    stderr = fopen("/dev/null", "w");
    stc_compile(&s, NULL);
    fclose(stderr);
    stderr = saved;
    free(text);
    return 0;
}

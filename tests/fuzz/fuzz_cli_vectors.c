/* libFuzzer harness for the command line's vector readers (src/cli/npy.c):
 * the first byte picks the .npy integer reader (--sources), the .npy float
 * reader (--cost) or the text reader; the rest is the file's content.
 * Messages go to stderr: run.sh passes -close_fd_mask=2 (libFuzzer keeps its
 * own output and the sanitizers' reports). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    int which = data[0] % 3;
    data++;
    size--;
    unsigned char *buf = malloc(size + 1); /* exact size: ASan sees any over-read */
    if (!buf)
        return 0;
    if (size)
        memcpy(buf, data, size);
    buf[size] = '\0';
    int64_t n = -1;
    if (which == 0) {
        int32_t *ids = NULL;
        int r = cli_npy_parse_ints(buf, size, "fuzz.npy", &ids, &n);
        if ((r == 0) != (ids != NULL) || (r == 0 && n < 0))
            abort();
        free(ids);
    } else if (which == 1) {
        double *v = NULL;
        int r = cli_npy_parse_vector(buf, size, "fuzz.npy", &v, &n);
        if ((r == 0) != (v != NULL) || (r == 0 && n < 0))
            abort();
        free(v);
    } else {
        double *v = NULL;
        if (memchr(buf, '\0', size) == NULL) {
            int r = cli_txt_parse_vector((const char *)buf, size, "fuzz.txt", &v, &n);
            if ((r == 0) != (v != NULL))
                abort();
        }
        free(v);
    }
    free(buf);
    return 0;
}

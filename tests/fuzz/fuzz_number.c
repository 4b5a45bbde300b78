/* libFuzzer harness: the readers' locale-free strtod (src/io/number.c)
 * against the C library's strtod in the C locale (a fuzzer process never
 * calls setlocale): same bits, same end. Inputs are restricted to the
 * syntax both accept (no hex, no leading blanks). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io/io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char s[1200];
    if (size >= sizeof s)
        size = sizeof s - 1;
    memcpy(s, data, size);
    s[size] = '\0';
    for (size_t i = 0; i < size; i++) /* strtod reads hex; ours does not */
        if (s[i] == 'x' || s[i] == 'X' || s[i] == 'p' || s[i] == 'P')
            s[i] = '0';
    if (s[0] == ' ' || s[0] == '\t' || s[0] == '\n' || s[0] == '\v' || s[0] == '\f' ||
        s[0] == '\r')
        return 0;
    const char *end;
    double got;
    int ok = mfmm_io_strtod(s, &end, &got);
    char *want_end;
    double want = strtod(s, &want_end);
    if (!ok) {
        if (want_end != s)
            abort();
        return 0;
    }
    if (end != want_end)
        abort();
    if (got != got) { /* NaN: both NaN */
        if (want == want)
            abort();
        return 0;
    }
    if (memcmp(&got, &want, sizeof got) != 0)
        abort();
    char buf[40];
    if (mfmm_io_format_double(buf, sizeof buf, got) < 0)
        abort();
    double back;
    if (!mfmm_io_strtod(buf, &end, &back) || *end || memcmp(&back, &got, sizeof got) != 0) {
        if (!(got != got))
            abort(); /* %.17g round trip */
    }
    return 0;
}

/* The command line's shared helpers: messages, argument parsing, the
 * signal flag, regular-file input, output files (temporary + rename) and
 * the output-is-an-input check. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <sys/statvfs.h>

#include "cli.h"
#include "io/io.h"

/* The one piece of process state: set by SIGINT/SIGTERM/SIGHUP (CLI only). */
static volatile sig_atomic_t interrupted_flag = 0;

static void on_signal(int sig)
{
    (void)sig;
    interrupted_flag = 1;
}

void cli_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    /* a closed terminal or ssh session: stop as on SIGINT, leaving no
     * temporary file */
    sigaction(SIGHUP, &sa, NULL);
}

int cli_interrupted(void)
{
    return interrupted_flag != 0;
}

void cli_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("meshfmm: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

int cli_usage_error(const char *sub, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "meshfmm %s: ", sub);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, " (try meshfmm %s --help)\n", sub);
    va_end(ap);
    return CLI_USAGE;
}

int cli_once(const char *sub, int c, uint32_t *seen)
{
    /* the value options, each with its bit */
    static const struct {
        int code;
        const char *name;
    } once[] = {{'o', "-o/--output"},
                {OPT_COST, "--cost"},
                {OPT_MAX_DISTANCE, "--max-distance"},
                {OPT_EXACT_START_RADIUS, "--exact-start-radius"},
                {OPT_MAX_POINTS, "--max-points"},
                {OPT_MAX_UNFOLD_STEPS, "--max-unfold-steps"},
                {OPT_STRETCH, "--stretch"},
                {OPT_RADII, "--radii"},
                {OPT_DTYPE, "--dtype"},
                {OPT_BACKEND, "--backend"},
                {OPT_SOURCES, "--sources"},
                {OPT_TARGETS, "--targets"},
                {OPT_THREADS, "--threads"},
                {OPT_MEMORY, "--memory"},
                {OPT_START, "--start"},
                {OPT_MAP, "--map"},
                {OPT_DISTANCES, "--distances"},
                {OPT_METHOD, "--method"},
                {'k', "-k/--count"}};
    for (unsigned i = 0; i < sizeof once / sizeof once[0]; i++) {
        if (once[i].code != c)
            continue;
        if (*seen & (UINT32_C(1) << i))
            return cli_usage_error(sub, "%s given twice; give it once", once[i].name);
        *seen |= UINT32_C(1) << i;
        return CLI_OK;
    }
    return CLI_OK;
}

int cli_free_bytes(const char *path, double *out)
{
    size_t n = strlen(path);
    char *dir = malloc(n + 2);
    if (!dir)
        return -1;
    memcpy(dir, path, n + 1);
    char *slash = strrchr(dir, '/');
    if (!slash)
        strcpy(dir, ".");
    else if (slash == dir)
        dir[1] = '\0';
    else
        *slash = '\0';
    struct statvfs fs;
    int rc = statvfs(dir, &fs);
    free(dir);
    if (rc != 0)
        return -1;
    *out = (double)fs.f_bavail * (double)fs.f_frsize;
    return 0;
}

const char *cli_format_bytes(double bytes, char *buf, size_t size)
{
    static const char *unit[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
    int u = 0;
    while (bytes >= 1024.0 && u < 5) {
        bytes /= 1024.0;
        u++;
    }
    snprintf(buf, size, u ? "%.3g %s" : "%.0f %s", bytes, unit[u]);
    return buf;
}

int cli_getopt_error(const char *sub, int c, char **argv)
{
    const char *arg = optind > 0 ? argv[optind - 1] : "?";
    if (c == ':')
        return cli_usage_error(sub, "option '%s' needs a value", arg);
    return cli_usage_error(sub, "unknown option '%s'", arg);
}

int cli_parse_int32(const char *s, int32_t *out)
{
    char *end;
    if (!s || !*s)
        return 0;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (errno || *end || v < INT32_MIN || v > INT32_MAX)
        return 0;
    *out = (int32_t)v;
    return 1;
}

int cli_parse_double(const char *s, double *out)
{
    const char *end;
    double v;
    if (!s || !*s || !mfmm_io_strtod(s, &end, &v) || *end || isnan(v))
        return 0;
    *out = v;
    return 1;
}

int cli_take_face_point(const char *face, int argc, char **argv, mfmm_source *s)
{
    int32_t fid;
    double w[3];
    if (optind + 3 > argc || !cli_parse_int32(face, &fid) ||
        !cli_parse_double(argv[optind], &w[0]) || !cli_parse_double(argv[optind + 1], &w[1]) ||
        !cli_parse_double(argv[optind + 2], &w[2]))
        return 0;
    optind += 3;
    mfmm_source x = {-1, fid, {w[0], w[1], w[2]}, 0.0};
    *s = x;
    return 1;
}

int cli_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext);
    if (n < m + 1 || path[n - m - 1] != '.')
        return 0;
    for (size_t i = 0; i < m; i++) {
        char c = path[n - m + i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != ext[i])
            return 0;
    }
    return 1;
}

/* ---- input ---- */

int cli_read_file(const char *path, unsigned char **data, size_t *size)
{
    *data = NULL;
    *size = 0;
    off_t fsize = 0;
    const char *why = NULL;
    int fd = mfmm_io_open_regular(path, &fsize, &why);
    if (fd == -2) {
        cli_error("'%s' is %s, not a data file", path, why);
        return -1;
    }
    if (fd < 0) {
        cli_error("cannot open '%s': %s", path, why);
        return -1;
    }
    if ((uint64_t)fsize >= (uint64_t)SIZE_MAX / 2) {
        cli_error("'%s' is too large", path);
        close(fd);
        return -1;
    }
    size_t want = (size_t)fsize, len = 0;
    unsigned char *buf = malloc(want + 2);
    if (!buf) {
        cli_error("out of memory reading '%s'", path);
        close(fd);
        return -1;
    }
    while (len < want + 1) {
        ssize_t got = read(fd, buf + len, want + 1 - len);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            cli_error("cannot read '%s': %s", path, strerror(errno));
            free(buf);
            close(fd);
            return -1;
        }
        if (got == 0)
            break;
        len += (size_t)got;
    }
    close(fd);
    if (len > want) {
        cli_error("'%s' grew while being read", path);
        free(buf);
        return -1;
    }
    buf[len] = '\0';
    *data = buf;
    *size = len;
    return 0;
}

int cli_check_output_not_input(const char *sub, const char *out, const char *const *inputs,
                               int n_inputs)
{
    struct stat so, si;
    if (!out || strcmp(out, "-") == 0 || stat(out, &so) != 0)
        return CLI_OK; /* a new file is no input */
    for (int i = 0; i < n_inputs; i++) {
        if (!inputs[i] || stat(inputs[i], &si) != 0)
            continue;
        if (so.st_dev == si.st_dev && so.st_ino == si.st_ino)
            return cli_usage_error(sub, "the output '%s' is the input '%s' (same file); "
                                        "refusing to overwrite an input", out, inputs[i]);
    }
    return CLI_OK;
}

/* ---- output ---- */

#ifdef NAME_MAX
#define CLI_NAME_MAX NAME_MAX
#else
#define CLI_NAME_MAX 255
#endif

int cli_output_open(cli_output *o, const char *path)
{
    memset(o, 0, sizeof *o);
    if (strcmp(path, "-") == 0) {
        o->f = stdout;
        return 0;
    }
    size_t n = strlen(path);
    o->path = malloc(n + 1);
    o->tmp_path = malloc(n + 8);
    if (!o->path || !o->tmp_path) {
        cli_error("out of memory");
        cli_output_abort(o);
        return -1;
    }
    memcpy(o->path, path, n + 1);
    /* the temporary name: the target's with 7 characters more, its file
     * name cut so that it stays within NAME_MAX (a valid target name of
     * 249-255 characters made mkstemp fail) */
    const char *slash = strrchr(path, '/');
    size_t dir = slash ? (size_t)(slash - path) + 1 : 0, keep = n;
    if (n - dir + 7 > CLI_NAME_MAX)
        keep = dir + (CLI_NAME_MAX - 7);
    memcpy(o->tmp_path, path, keep);
    memcpy(o->tmp_path + keep, ".XXXXXX", 8);
    /* mkstemp: O_CREAT | O_EXCL, a fresh name; never follows a symlink. */
    int fd = mkstemp(o->tmp_path);
    if (fd < 0) {
        cli_error("cannot create a temporary file beside '%s': %s", path, strerror(errno));
        free(o->tmp_path);
        o->tmp_path = NULL;
        cli_output_abort(o);
        return -1;
    }
    /* mkstemp makes 0600; give the file the mode a plain create would. */
    mode_t mask = umask(0);
    umask(mask);
    if (fchmod(fd, 0666 & ~mask) != 0) {
        /* harmless: the file stays private */
    }
    o->f = fdopen(fd, "wb");
    if (!o->f) {
        cli_error("cannot write '%s': %s", o->tmp_path, strerror(errno));
        close(fd);
        cli_output_abort(o);
        return -1;
    }
    return 0;
}

int cli_output_close(cli_output *o, int bad)
{
    if (!o->f)
        return -1;
    int e = 0;
    if (fflush(o->f) != 0 || ferror(o->f)) {
        bad = 1;
        e = errno;
    }
    if (!o->path) { /* stdout */
        o->f = NULL;
        if (bad)
            cli_error("cannot write to standard output: %s", e ? strerror(e) : "write error");
        return bad ? -1 : 0;
    }
    if (!bad && fsync(fileno(o->f)) != 0 && errno != EINVAL) {
        bad = 1;
        e = errno;
    }
    if (fclose(o->f) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    o->f = NULL;
    if (cli_interrupted()) {
        cli_output_abort(o);
        return -1;
    }
    if (!bad && rename(o->tmp_path, o->path) != 0) {
        bad = 1;
        e = errno;
    }
    if (bad) {
        cli_error("cannot write '%s': %s", o->path, e ? strerror(e) : "write error");
        cli_output_abort(o);
        return -1;
    }
    free(o->path);
    free(o->tmp_path);
    o->path = o->tmp_path = NULL;
    return 0;
}

void cli_output_abort(cli_output *o)
{
    if (o->f && o->f != stdout)
        fclose(o->f);
    else if (o->f)
        fflush(o->f);
    o->f = NULL;
    if (o->tmp_path)
        remove(o->tmp_path);
    free(o->path);
    free(o->tmp_path);
    o->path = o->tmp_path = NULL;
}

int cli_put_double(FILE *f, double x)
{
    if (isinf(x))
        return fputs(x > 0 ? "inf" : "-inf", f);
    char buf[40];
    if (mfmm_io_format_double(buf, sizeof buf, x) < 0)
        return EOF;
    return fputs(buf, f);
}

void cli_note_sources_in_no_face(const char *sub, int64_t count, int32_t first)
{
    if (count == 1)
        fprintf(stderr, "meshfmm %s: note: source vertex %ld is in no face: it reaches only "
                        "itself (0 there, +inf elsewhere)\n", sub, (long)first);
    else if (count > 1)
        fprintf(stderr, "meshfmm %s: note: %lld source vertices are in no face (the first: "
                        "%ld): each reaches only itself (0 there, +inf elsewhere)\n", sub,
                (long long)count, (long)first);
}

int cli_write_obj(const char *path, const double *V, int32_t nv, const int32_t *F, int32_t nf,
                  const char *comment)
{
    cli_output out;
    if (cli_output_open(&out, path))
        return -1;
    FILE *f = out.f;
    int bad = fprintf(f, "# %s\n", comment) < 0;
    for (int32_t i = 0; i < nv && !bad && !cli_interrupted(); i++)
        for (int k = 0; k < 3 && !bad; k++)
            bad = fputs(k ? " " : "v ", f) < 0 || cli_put_double(f, V[3 * i + k]) < 0 ||
                  (k == 2 && fputc('\n', f) == EOF);
    for (int32_t i = 0; i < nf && !bad && !cli_interrupted(); i++)
        bad = fprintf(f, "f %ld %ld %ld\n", (long)F[3 * i] + 1, (long)F[3 * i + 1] + 1,
                      (long)F[3 * i + 2] + 1) < 0;
    return cli_output_close(&out, bad);
}

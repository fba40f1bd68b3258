/*
** main.c: plcrt's entry point and housekeeping thread: configuration,
** start-up, status line, periodic retain saves, signals, shutdown.
*/
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>
#include "config.h"
#include "force.h"
#include "log.h"
#include "mbmap.h"
#include "mbserver.h"
#include "mbrtu.h"
#include "program.h"
#include "retain.h"
#include "scan.h"
#include "sdnotify.h"
#include "tags.h"
#include "trace.h"
#include "tracemb.h"

#define PLCRT_VERSION "0.1.0"

static void usage(FILE *f)
{
    fprintf(f,
        "usage: plcrt [-c FILE.ini] [--check-config] [--help] [--version]\n"
        "Runs the linked PLC program (configuration %s) every %.3f ms.\n"
        "  -c, --config FILE   configuration file (docs/config.md); defaults otherwise\n"
        "      --check-config  check the configuration (file, program, this host) and exit\n"
        "      --tags DIR      check it, write the tag list (TAGS.csv, TAGS.json: tags.h) into DIR, exit\n"
        "  -h, --help          this text\n"
        "  -V, --version       version and linked program\n"
        "Signals: SIGINT/SIGTERM/SIGHUP/SIGQUIT stop (outputs safe, retain saved), SIGUSR1 prints statistics.\n",
        plc_program_linked.name, *plc_program_linked.ticktime / 1e6);
}

typedef struct retained {
    retain_var *rv;       /* the files' view: copies in buf */
    scan_sample *smp;     /* variable -> copy */
    scan_sample *back;    /* copy -> variable (after loading) */
    size_t n;
    uint64_t gen;
} retained;

static int retained_setup(retained *r, const plc_program *p)
{
    size_t n = 0;
    for (size_t i = 0; i < p->nvars; i++) n += p->vars[i].retain;
    r->n = n;
    r->rv = calloc(n + 1, sizeof *r->rv);
    r->smp = calloc(n + 1, sizeof *r->smp);
    r->back = calloc(n + 1, sizeof *r->back);
    if (!r->rv || !r->smp || !r->back) return -1;
    size_t k = 0;
    for (size_t i = 0; i < p->nvars; i++) {
        const plc_var *v = &p->vars[i];
        if (!v->retain) continue;
        void *copy = calloc(1, v->size ? v->size : 1);
        if (!copy) return -1;
        r->rv[k] = (retain_var){ v->path, v->type, copy, v->size };
        r->smp[k] = (scan_sample){ plc_var_addr(v), copy, v->size };
        r->back[k] = (scan_sample){ copy, plc_var_addr(v), v->size };
        k++;
    }
    return 0;
}

static void retain_now(scan *s, retained *r, const plc_config *c, int running)
{
    char err[512];
    if (!c->retain_file[0] || !r->n) return;
    if (scan_sample_now(s, r->smp, r->n, running, 1000)) {
        plc_log(LOG_ERROR, "retain: the scan did not hand over the variables in time; not saved");
        atomic_fetch_add(&s->retain_errors, 1);
        return;
    }
    if (retain_save(c->retain_file, r->rv, r->n, ++r->gen, err, sizeof err)) {
        plc_log(LOG_ERROR, "retain: %s", err);
        atomic_fetch_add(&s->retain_errors, 1);
    } else {
        atomic_fetch_add(&s->retain_saves, 1);
    }
}

/* One value for the status line. */
static void fmt_var(char *out, size_t n, const plc_var *v, const void *d)
{
    const char *t = v->type;
    int8_t i8; uint8_t u8; int16_t i16; uint16_t u16; int32_t i32; uint32_t u32;
    int64_t i64; uint64_t u64; float f; double g;
    if (!strcasecmp(t, "BOOL") || !strcasecmp(t, "USINT") || !strcasecmp(t, "BYTE")) { memcpy(&u8, d, 1); snprintf(out, n, "%u", u8); }
    else if (!strcasecmp(t, "SINT")) { memcpy(&i8, d, 1); snprintf(out, n, "%d", i8); }
    else if (!strcasecmp(t, "INT")) { memcpy(&i16, d, 2); snprintf(out, n, "%d", i16); }
    else if (!strcasecmp(t, "UINT") || !strcasecmp(t, "WORD")) { memcpy(&u16, d, 2); snprintf(out, n, "%u", u16); }
    else if (!strcasecmp(t, "DINT")) { memcpy(&i32, d, 4); snprintf(out, n, "%" PRId32, i32); }
    else if (!strcasecmp(t, "UDINT") || !strcasecmp(t, "DWORD")) { memcpy(&u32, d, 4); snprintf(out, n, "%" PRIu32, u32); }
    else if (!strcasecmp(t, "LINT")) { memcpy(&i64, d, 8); snprintf(out, n, "%" PRId64, i64); }
    else if (!strcasecmp(t, "ULINT") || !strcasecmp(t, "LWORD")) { memcpy(&u64, d, 8); snprintf(out, n, "%" PRIu64, u64); }
    else if (!strcasecmp(t, "REAL")) { memcpy(&f, d, 4); snprintf(out, n, "%.3f", f); }
    else if (!strcasecmp(t, "LREAL")) { memcpy(&g, d, 8); snprintf(out, n, "%.3f", g); }
    else snprintf(out, n, "(%s)", t);
}

static const char *short_path(const char *p)
{
    const char *q = strchr(p, '.');           /* drop the configuration name */
    return q ? q + 1 : p;
}

/* The configuration, checked whole: the file (config_load), then against
** the program (status_vars, the symbol map, even with Modbus disabled),
** then against this host (config_check_host). The same for --check-config
** and the start. 0, or the exit status (2) after the message. */
static int configure(plc_config *cfg, const char *file, const plc_program *prog,
                     const plc_var *status[CFG_MAX_STATUS], mb_shared **mb)
{
    char err[800];
    if (config_defaults(cfg, err, sizeof err) || (file && config_load(cfg, file, err, sizeof err))) {
        fprintf(stderr, "plcrt: %s\n", err);
        return 2;
    }
    plc_log_level(cfg->log_level);
    if (!*prog->ticktime) { fprintf(stderr, "plcrt: the program has no task interval\n"); return 2; }

    /* The program's own initialisation first: located and external
    ** variables get their addresses there. */
    prog->init();

    for (int i = 0; i < cfg->nstatus; i++)
        if (!(status[i] = plc_var_find(prog, cfg->status_vars[i]))) {
            config_msg(cfg, "plc", "status_vars", err, sizeof err, "no variable %s in the program (see VARIABLES.csv)",
                       cfg->status_vars[i]);
            fprintf(stderr, "plcrt: %s\n", err);
            return 2;
        }
    if (!(*mb = mb_new(cfg, prog, err, sizeof err))) {
        fprintf(stderr, "plcrt: %s\n", err);
        return 2;
    }
    if (!cfg->mb_enabled && !cfg->rtu_device[0]) {     /* checked, not served */
        mb_free(*mb);
        *mb = NULL;
    }
    size_t nretained = 0;
    for (size_t i = 0; i < prog->nvars; i++) nretained += prog->vars[i].retain != 0;
    if (config_check_host(cfg, nretained, err, sizeof err)) {
        fprintf(stderr, "plcrt: %s\n", err);
        return 2;
    }
    return 0;
}

/* Stop the scan and the Modbus server (a request in flight gets its reply),
** land what clients were told was written (so that a retained value is the
** last one acknowledged), then the outputs to their safe state: nothing
** lands in them after that. Save, release, and say so in one line; after
** SIGTERM (a service manager, a test) the statistics are printed too, after
** Ctrl-C (SIGINT, a person at the terminal) only that line. */
/* The Modbus servers, TCP (srv, may be NULL) and RTU: stopped, a request
** being served answered first. */
static mb_rtu *rtu_srv;
static void servers_stop(mb_server *srv)
{
    mb_server_stop(srv);
    mb_rtu_stop(rtu_srv);
    rtu_srv = NULL;
}

/* Once the scan no longer touches them: the image's outputs zeroed, the
** backend's physical outputs to their safe state (0 V, off). */
static void outputs_safe(plc_config *cfg)
{
    memset(plc_img.qx, 0, sizeof plc_img.qx);
    memset(plc_img.qb, 0, sizeof plc_img.qb);
    memset(plc_img.qw, 0, sizeof plc_img.qw);
    memset(plc_img.qd, 0, sizeof plc_img.qd);
    memset(plc_img.ql, 0, sizeof plc_img.ql);
    cfg->io->safe_state(cfg->io_state, &plc_img);
}

static void shut_down(scan *sc, pthread_t th, mb_server *srv, mb_shared *mb, plc_config *cfg, retained *ret,
                      int sig)
{
    atomic_store(&sc->stop, 1);
    pthread_join(th, NULL);
    servers_stop(srv);
    if (mb) mb_drain(mb, &plc_img);
    outputs_safe(cfg);
    uint64_t errs = atomic_load(&sc->retain_errors);
    retain_now(sc, ret, cfg, 0);
    if (sig != SIGINT) stats_print(stderr, &sc->stats, sc->period_ns);
    cfg->io->close(cfg->io_state);
    mb_free(mb);
    if (!cfg->retain_file[0] || !ret->n)
        fprintf(stderr, "plcrt: outputs safe (DAC 0 V), nothing retained\n");
    else if (atomic_load(&sc->retain_errors) != errs)
        fprintf(stderr, "plcrt: outputs safe (DAC 0 V), retain NOT saved to %s (see above)\n", cfg->retain_file);
    else
        fprintf(stderr, "plcrt: outputs safe (DAC 0 V), retain saved to %s\n", cfg->retain_file);
}

/* One plcrt per retain file: two would save their generations over each
** other's (and each load the other's). FILE.lock holds the owner's pid
** under an flock that ends with the process. 0, or -1 with a message. */
static int retain_lock(const plc_config *c, char *err, size_t n)
{
    char lock[sizeof c->retain_file + 8];
    snprintf(lock, sizeof lock, "%s.lock", c->retain_file);
    int fd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
        config_msg(c, "retain", "file", err, n, "cannot create %s: %s", lock, strerror(errno));
        return -1;
    }
    if (flock(fd, LOCK_EX | LOCK_NB)) {
        char pid[24] = "";
        ssize_t r = read(fd, pid, sizeof pid - 1);
        pid[r > 0 ? r : 0] = 0;
        pid[strcspn(pid, "\n")] = 0;
        config_msg(c, "retain", "file", err, n, "%s is in use by another plcrt (pid %s): two would overwrite each "
                   "other's generations; give each its own [retain] file", c->retain_file, pid[0] ? pid : "?");
        close(fd);
        return -1;
    }
    if (ftruncate(fd, 0) == 0) dprintf(fd, "%d\n", (int)getpid());
    return 0;                        /* fd stays open, and locked, until the end */
}

static const char *sig_name(int sig)
{
    switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP (the terminal closed)";
    case SIGQUIT: return "SIGQUIT";
    default: return "a signal";
    }
}

/* A stop signal already pending (taken), or 0. */
static int stop_pending(const sigset_t *sigs)
{
    sigset_t p;
    if (sigpending(&p)) return 0;
    static const int stops[] = { SIGINT, SIGTERM, SIGHUP, SIGQUIT };
    for (size_t i = 0; i < sizeof stops / sizeof stops[0]; i++)
        if (sigismember(&p, stops[i])) {
            struct timespec zero = { 0, 0 };
            sigtimedwait(sigs, NULL, &zero);
            return stops[i];
        }
    return 0;
}

/* The program has not returned within [scan] watchdog_ms (an endless loop,
** say): the scan no longer touches the I/O (scan_watchdog), so the outputs
** are put in their safe state from here, and plcrt ends with status 3. The
** scan thread is stuck in the program: it cannot hand over a consistent
** copy of the retained variables, so the retain file keeps the last
** generation saved. */
static _Noreturn void watchdog_halt(scan *sc, mb_server *srv, plc_config *cfg)
{
    double ms = (double)(scan_now_ns() - atomic_load(&sc->program_ns)) / 1e6;
    plc_log(LOG_ERROR, "watchdog: the program has been running for %.0f ms in one cycle, beyond [scan] watchdog_ms "
            "= %d (an endless loop? a loop bound from a variable?): outputs to their safe state, plcrt stops",
            ms, cfg->watchdog_ms);
    servers_stop(srv);
    outputs_safe(cfg);
    if (!cfg->retain_file[0])
        fprintf(stderr, "plcrt: stopped by the watchdog: outputs safe (DAC 0 V), nothing retained\n");
    else
        fprintf(stderr, "plcrt: stopped by the watchdog: outputs safe (DAC 0 V), retain NOT saved: %s keeps "
                "the generation saved last\n", cfg->retain_file);
    fflush(stdout);
    fflush(stderr);
    _exit(3);
}

int main(int argc, char **argv)
{
    static const struct option opts[] = {
        { "config", required_argument, 0, 'c' }, { "check-config", no_argument, 0, 'k' },
        { "help", no_argument, 0, 'h' }, { "version", no_argument, 0, 'V' },
        { "tags", required_argument, 0, 't' }, { 0, 0, 0, 0 }
    };
    const char *file = NULL, *tags = NULL;
    int check = 0, o;
    char err[600];
    while ((o = getopt_long(argc, argv, "c:hV", opts, NULL)) != -1) {
        switch (o) {
        case 'c': file = optarg; break;
        case 'k': check = 1; break;
        case 't': tags = optarg; check = 1; break;
        case 'h': usage(stdout); return 0;
        case 'V': printf("plcrt %s (program %s, %.3f ms)\n", PLCRT_VERSION, plc_program_linked.name,
                         *plc_program_linked.ticktime / 1e6); return 0;
        default: usage(stderr); return 2;
        }
    }
    if (optind < argc) { fprintf(stderr, "plcrt: unexpected argument '%s'\n", argv[optind]); usage(stderr); return 2; }
    if (file && !*file) {            /* plcrt -c "$CFG" with CFG unset */
        fprintf(stderr, "plcrt: -c needs the name of a configuration file (an empty name was given; "
                "leave -c out for the defaults)\n");
        return 2;
    }

    static plc_config cfg;
    const plc_program *prog = &plc_program_linked;
    const plc_var *status[CFG_MAX_STATUS];
    mb_shared *mb = NULL;
    int st = configure(&cfg, file, prog, status, &mb);
    if (st) return st;
    uint64_t period = *prog->ticktime;
    if (tags && tags_write(prog, mb, tags, err, sizeof err)) {
        fprintf(stderr, "plcrt: tag list: %s\n", err);
        return 2;
    }
    if (check) {
        printf("%s: configuration OK (backend %s, %d Modbus symbols)\n",
               file ? file : "(defaults)", cfg.backend, cfg.nsymbols);
        return 0;
    }

    /* From here on a stop signal is taken by the housekeeping loop (or the
    ** check before the first cycle below), never by its default action: the
    ** backend may hold outputs from its open on, and they go to their safe
    ** state on every way out. SIGHUP (the terminal closed) and SIGQUIT
    ** (Ctrl-backslash) stop the way SIGTERM does, unless plcrt was started
    ** with them ignored (nohup): blocked, they would be queued and taken. */
    sigset_t sigs;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT); sigaddset(&sigs, SIGTERM);
    sigaddset(&sigs, SIGUSR1); sigaddset(&sigs, SIGPIPE);
    static const int optional[] = { SIGHUP, SIGQUIT };
    for (size_t i = 0; i < sizeof optional / sizeof optional[0]; i++) {
        struct sigaction sa;
        if (sigaction(optional[i], NULL, &sa) == 0 && sa.sa_handler != SIG_IGN) sigaddset(&sigs, optional[i]);
    }
    pthread_sigmask(SIG_BLOCK, &sigs, NULL);

    /* retain */
    retained ret = {0};
    if (retained_setup(&ret, prog)) { fprintf(stderr, "plcrt: out of memory\n"); return 1; }
    if (cfg.retain_file[0] && ret.n && retain_lock(&cfg, err, sizeof err)) {
        fprintf(stderr, "plcrt: %s\n", err);
        return 2;
    }
    if (cfg.retain_file[0] && ret.n) {
        scan_sample_now(NULL, ret.smp, ret.n, 0, 0);     /* initial values as default */
        if (!retain_load(cfg.retain_file, ret.rv, ret.n, &ret.gen))
            scan_sample_now(NULL, ret.back, ret.n, 0, 0);
    }

    /* the Modbus port before any I/O: a second plcrt started on the same
    ** configuration stops here, before its backend could reset the nodes
    ** the first one drives */
    mb_server *srv = NULL;
    if (mb && cfg.mb_enabled && !(srv = mb_server_listen(&cfg, mb, err, sizeof err))) {
        int e = errno;
        char msg[800];
        config_msg(&cfg, "modbus", e == EADDRINUSE || e == EACCES ? "port" : "bind", msg, sizeof msg, "%s%s", err,
                   e == EADDRINUSE ? " (another plcrt running on this configuration? nothing was opened)" : "");
        fprintf(stderr, "plcrt: %s\n", msg);
        return 2;
    }

    /* the serial line of [modbus_rtu], also before any I/O */
    if (mb && cfg.rtu_device[0] && !(rtu_srv = mb_rtu_open(&cfg, mb, err, sizeof err))) {
        char msg[800];
        config_msg(&cfg, "modbus_rtu", "device", msg, sizeof msg, "%s", err);
        fprintf(stderr, "plcrt: %s\n", msg);
        servers_stop(srv);
        return 2;
    }

    /* I/O */
    if (cfg.io->open(cfg.io_state, &plc_img, period, err, sizeof err)) {
        fprintf(stderr, "plcrt: %s: %s\n", cfg.file[0] ? cfg.file : "(defaults)", err);
        servers_stop(srv);
        return 2;
    }

    static scan sc;
    sc.prog = prog; sc.io = cfg.io; sc.io_state = cfg.io_state; sc.mb = mb;
    sc.period_ns = period;
    sc.started_ns = scan_now_ns();
    struct timespec rt;
    clock_gettime(CLOCK_REALTIME, &rt);
    sc.base_sec = rt.tv_sec; sc.base_nsec = rt.tv_nsec;
    stats_reset(&sc.stats);
    /* trace and forcing: over Modbus only; buffers allocated (and touched) now */
    trace *tr = NULL;
    forcing *fo = NULL;
    tracemb *tb = NULL;
    if (mb) {
        if (!(tr = trace_new((uint32_t)cfg.trace_samples)) || !(fo = force_new(prog, cfg.allow_force))
            || !(tb = tb_new(tr, fo, prog, period))) {
            fprintf(stderr, "plcrt: out of memory for the trace ([trace] samples = %d)\n", cfg.trace_samples);
            return 1;
        }
        mb->block = tb_block(tb);
        sc.trace = tr;
        sc.force = fo;
        if (cfg.allow_force) plc_log(LOG_WARN, "forcing allowed ([debug] allow_force)");
    }
    if (mb) {
        uint16_t diag[MB_DIAG_ALL];
        scan_diag(&sc, diag);
        mb_publish(mb, &plc_img, diag);
    }

    /* a stop asked for during the start-up: no cycle runs at all, and no
    ** client has been told a write was taken (nothing served yet: from
    ** mb_server_run on, a stop takes the orderly way, writes landed) */
    int early = stop_pending(&sigs);
    if (early) {
        servers_stop(srv);
        cfg.io->safe_state(cfg.io_state, &plc_img);
        cfg.io->close(cfg.io_state);
        fprintf(stderr, "plcrt: %s during the start-up: stopped before the first cycle, outputs safe (DAC 0 V), "
                "retain file untouched\n", sig_name(early));
        return 0;
    }
    if ((srv && mb_server_run(srv, err, sizeof err)) || (rtu_srv && mb_rtu_run(rtu_srv, err, sizeof err))) {
        fprintf(stderr, "plcrt: %s\n", err);
        servers_stop(srv);
        cfg.io->safe_state(cfg.io_state, &plc_img);
        cfg.io->close(cfg.io_state);
        return 1;
    }

    if (cfg.lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE))
        plc_log(LOG_WARN, "mlockall: %s: memory may be paged out (raise RLIMIT_MEMLOCK or run with CAP_IPC_LOCK)", strerror(errno));

    pthread_attr_t at;
    pthread_attr_init(&at);
    if (cfg.cpu >= 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(cfg.cpu, &set);
        pthread_attr_setaffinity_np(&at, sizeof set, &set);
    }
    pthread_t th;
    int rt_ok = 0;
    if (cfg.priority > 0) {
        struct sched_param sp = { .sched_priority = cfg.priority };
        pthread_attr_setinheritsched(&at, PTHREAD_EXPLICIT_SCHED);
        pthread_attr_setschedpolicy(&at, SCHED_FIFO);
        pthread_attr_setschedparam(&at, &sp);
        rt_ok = !pthread_create(&th, &at, scan_thread, &sc);
        if (!rt_ok) {
            plc_log(LOG_WARN, "SCHED_FIFO priority %d refused (%s): the scan runs with normal priority and its timing is not guaranteed",
                    cfg.priority, "run as root or grant CAP_SYS_NICE");
            pthread_attr_setinheritsched(&at, PTHREAD_INHERIT_SCHED);
        }
    }
    if (!rt_ok && pthread_create(&th, &at, scan_thread, &sc)) {
        fprintf(stderr, "plcrt: cannot start the scan thread\n");
        return 1;
    }
    pthread_attr_destroy(&at);
    plc_log(LOG_INFO, "running %s every %.3f ms (%s), backend %s", prog->name, period / 1e6,
            rt_ok ? "SCHED_FIFO" : "normal priority", cfg.backend);

    /* housekeeping */
    sdnotify notify;   /* the service manager: ready, alive (sdnotify.h) */
    sdnotify_open(&notify);
    uint64_t t_status = scan_now_ns(), t_retain = t_status, t_over = t_status;
    uint64_t last_over = 0;
    int stop_sig = SIGTERM;
    uint8_t sbuf[CFG_MAX_STATUS][64];
    scan_sample ss[CFG_MAX_STATUS];
    for (int i = 0; i < cfg.nstatus; i++)
        ss[i] = (scan_sample){ plc_var_addr(status[i]), sbuf[i], status[i]->size <= 64 ? status[i]->size : 64 };
    /* the watchdog looks a few times within its time */
    long wd_ns = cfg.watchdog_ms ? (long)cfg.watchdog_ms * 1000000 / 4 : 200000000;
    if (wd_ns > 200000000) wd_ns = 200000000;
    if (wd_ns < 10000000) wd_ns = 10000000;
    for (;;) {
        struct timespec to = { 0, wd_ns };
        int sig = sigtimedwait(&sigs, NULL, &to);
        if (scan_watchdog(&sc, (uint64_t)cfg.watchdog_ms * 1000000u))
            watchdog_halt(&sc, srv, &cfg);
        if (sig == SIGINT || sig == SIGTERM || sig == SIGHUP || sig == SIGQUIT) {
            if (sig != SIGINT) plc_log(LOG_INFO, "%s: stopping", sig_name(sig));
            else if (isatty(2)) fputc('\n', stderr);   /* past the terminal's ^C */
            stop_sig = sig;
            break;
        }
        if (sig == SIGUSR1) stats_print(stderr, &sc.stats, period);
        uint64_t now = scan_now_ns();
        sdnotify_tick(&notify, now, atomic_load(&sc.stats.cycles));
        stat_summary es, ls;
        stat_summarize(&sc.stats.exec, &es);
        stat_summarize(&sc.stats.lat, &ls);
        atomic_store(&sc.exec_p99_ns, es.p99_ns);
        atomic_store(&sc.lat_p99_ns, ls.p99_ns);
        uint64_t ov = atomic_load(&sc.stats.overruns);
        if (ov != last_over && now - t_over >= (uint64_t)cfg.overrun_log_interval * 1000000000u) {
            plc_log(LOG_WARN, "%" PRIu64 " overrun(s) (total %" PRIu64 ", %" PRIu64 " periods skipped, %" PRIu64
                    " with the program alone over the period); worst execution %.1f us, worst wake latency %.1f us",
                    ov - last_over, ov, (uint64_t)atomic_load(&sc.stats.missed),
                    (uint64_t)atomic_load(&sc.stats.overruns_exec), es.max_ns / 1e3, ls.max_ns / 1e3);
            last_over = ov;
            t_over = now;
        }
        if (cfg.status_interval && now - t_status >= (uint64_t)cfg.status_interval * 1000000000u) {
            t_status = now;
            char line[1024];
            int nf = fo ? force_count(fo) : 0, k = 0;
            if (nf) k = snprintf(line, sizeof line, "FORCED %d  ", nf);
            k += snprintf(line + k, sizeof line - (size_t)k, "cycles %" PRIu64 "  overruns %" PRIu64 "  worst latency %.1f us",
                          (uint64_t)atomic_load(&sc.stats.cycles), ov, ls.max_ns / 1e3);
            if (cfg.nstatus && !scan_sample_now(&sc, ss, (size_t)cfg.nstatus, 1, 500)) {
                for (int i = 0; i < cfg.nstatus && k < (int)sizeof line - 80; i++) {
                    char val[64];
                    fmt_var(val, sizeof val, status[i], sbuf[i]);
                    int forced = fo && force_is_forced(fo, (uint32_t)(status[i] - prog->vars));
                    k += snprintf(line + k, sizeof line - (size_t)k, "  %s %s%s", short_path(status[i]->path), val,
                                  forced ? " (forced)" : "");
                }
            }
            printf("%s\n", line);
            fflush(stdout);
        }
        if (cfg.retain_period && now - t_retain >= (uint64_t)cfg.retain_period * 1000000000u) {
            t_retain = now;
            retain_now(&sc, &ret, &cfg, 1);
        }
    }

    sdnotify_close(&notify);
    shut_down(&sc, th, srv, mb, &cfg, &ret, stop_sig);
    tb_free(tb);
    force_free(fo);
    trace_free(tr);
    return 0;
}

/*
 * wsph_client.c -- a wavesph coupling client in plain C99 + POSIX sockets, written from
 * protocol/PROTOCOL.md alone. It imposes a linear (Airy) wave at the SPH inlet nodes.
 *
 *   usage: wsph_client HOST PORT RUN_ID N_WINDOWS [H T WINDOW]
 *     H      wave height [m]            (default 0.05)
 *     T      wave period [s]            (default 1.0)
 *     WINDOW coupling window [s]        (default: window_max from WELCOME)
 *
 * Handshake (HELLO/WELCOME), GETNODES, then per window SET + SOLVE -> RESULT, then BYE.
 * Prints one line per window:  "RESULT <t> <steps> <eta_0> ... <eta_G-1>"  (eta in m above
 * still water, "dry" for a dry gauge). Exit status: 0 ok, 2 usage/network, 3 server ERROR,
 * 4 protocol violation by the server.
 *
 * Every integer and float is encoded byte by byte as little-endian, so this also works on a
 * big-endian machine. Every read has a timeout (SO_RCVTIMEO).
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

enum { WSPH_HELLO = 1, WSPH_WELCOME = 2, WSPH_GETNODES = 3, WSPH_NODES = 4, WSPH_SET = 5,
       WSPH_SOLVE = 6, WSPH_GET = 7, WSPH_RESULT = 8, WSPH_GOBACK = 9, WSPH_ERROR = 10,
       WSPH_BYE = 11 };
#define WSPH_VERSION 1
#define WSPH_HEADER 16
#define WSPH_MAX_PAYLOAD (16u * 1024u * 1024u)
#define READ_TIMEOUT_S 600  /* 1.0 has no keep-alive: a fresh server compiles for minutes (PROTOCOL.md, section 6) */

/* ---------- little-endian byte buffer ---------- */
typedef struct { unsigned char *p; size_t len, cap; } buf_t;

static void need(buf_t *b, size_t n) {
    if (b->len + n > b->cap) {
        b->cap = (b->len + n) * 2;
        b->p = realloc(b->p, b->cap);
        if (!b->p) { perror("realloc"); exit(2); }
    }
}
static void put_u16(buf_t *b, uint16_t v) { need(b, 2); b->p[b->len++] = v & 0xff; b->p[b->len++] = v >> 8; }
static void put_u32(buf_t *b, uint32_t v) {
    need(b, 4);
    for (int i = 0; i < 4; i++) b->p[b->len++] = (v >> (8 * i)) & 0xff;
}
static void put_f64(buf_t *b, double d) {
    uint64_t v; memcpy(&v, &d, 8); need(b, 8);
    for (int i = 0; i < 8; i++) b->p[b->len++] = (v >> (8 * i)) & 0xff;
}
static void put_bytes(buf_t *b, const void *s, size_t n) { need(b, n); memcpy(b->p + b->len, s, n); b->len += n; }
static void put_text(buf_t *b, const char *s) { put_u32(b, (uint32_t)strlen(s)); put_bytes(b, s, strlen(s)); }
static void put_f64_array(buf_t *b, const double *a, uint32_t n) { put_u32(b, n); for (uint32_t i = 0; i < n; i++) put_f64(b, a[i]); }

/* ---------- reader with bounds checks ---------- */
typedef struct { const unsigned char *p; size_t len, pos; int bad; } rd_t;

static int avail(rd_t *r, size_t n) { if (r->bad || r->len - r->pos < n) { r->bad = 1; return 0; } return 1; }
static uint32_t get_u32(rd_t *r) {
    if (!avail(r, 4)) return 0;
    uint32_t v = 0; for (int i = 0; i < 4; i++) v |= (uint32_t)r->p[r->pos + i] << (8 * i);
    r->pos += 4; return v;
}
static double get_f64(rd_t *r) {
    if (!avail(r, 8)) return 0.0;
    uint64_t v = 0; for (int i = 0; i < 8; i++) v |= (uint64_t)r->p[r->pos + i] << (8 * i);
    r->pos += 8; double d; memcpy(&d, &v, 8);
    if (!isfinite(d)) r->bad = 1;
    return d;
}
static void get_text(rd_t *r, char *out, size_t outsz) {
    uint32_t n = get_u32(r);
    if (!avail(r, n)) { out[0] = 0; return; }
    size_t k = n < outsz - 1 ? n : outsz - 1;
    memcpy(out, r->p + r->pos, k); out[k] = 0; r->pos += n;
}
/* array whose count must equal `expect` (from WELCOME); out has room for expect values */
static void get_f64_array(rd_t *r, double *out, uint32_t expect) {
    uint32_t n = get_u32(r);
    if (n != expect || !avail(r, (size_t)8 * n)) { r->bad = 1; return; }
    for (uint32_t i = 0; i < n; i++) out[i] = get_f64(r);
}
static void get_u32_array(rd_t *r, uint32_t *out, uint32_t expect) {
    uint32_t n = get_u32(r);
    if (n != expect || !avail(r, (size_t)4 * n)) { r->bad = 1; return; }
    for (uint32_t i = 0; i < n; i++) out[i] = get_u32(r);
}

/* ---------- frames over TCP ---------- */
static int sock = -1;
static uint32_t seq = 0;

static void send_frame(uint16_t type, const buf_t *payload, buf_t *out) {
    /* appends the frame to `out`; the caller writes `out` (so SET + SOLVE go in one write) */
    put_bytes(out, "WSPH", 4); put_u16(out, WSPH_VERSION); put_u16(out, type);
    put_u32(out, ++seq); put_u32(out, payload ? (uint32_t)payload->len : 0);
    if (payload) put_bytes(out, payload->p, payload->len);
}
static void write_all(const buf_t *b) {
    size_t off = 0;
    while (off < b->len) {
        ssize_t k = send(sock, b->p + off, b->len - off, 0);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) { perror("send"); exit(2); }
        off += (size_t)k;
    }
}
static void read_all(unsigned char *p, size_t n) {
    size_t off = 0;
    while (off < n) {
        ssize_t k = recv(sock, p + off, n - off, 0);
        if (k < 0 && errno == EINTR) continue;
        if (k < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            fprintf(stderr, "timeout: no reply from the server within %d s\n", READ_TIMEOUT_S); exit(2);
        }
        if (k == 0) { fprintf(stderr, "server closed the connection\n"); exit(2); }
        if (k < 0) { perror("recv"); exit(2); }
        off += (size_t)k;
    }
}

/* Reads one frame; an ERROR frame ends the program; returns the payload (caller frees). */
static unsigned char *recv_frame(uint16_t expect_type, size_t *len) {
    unsigned char h[WSPH_HEADER];
    read_all(h, WSPH_HEADER);
    rd_t r = { h, WSPH_HEADER, 4, 0 };
    if (memcmp(h, "WSPH", 4) != 0) { fprintf(stderr, "protocol: bad magic\n"); exit(4); }
    uint16_t version = h[4] | h[5] << 8, type = h[6] | h[7] << 8;
    r.pos = 8;
    uint32_t rseq = get_u32(&r), n = get_u32(&r);
    if (version != WSPH_VERSION) { fprintf(stderr, "protocol: server speaks version %u\n", version); exit(4); }
    if (n > WSPH_MAX_PAYLOAD) { fprintf(stderr, "protocol: frame of %u bytes over the limit\n", n); exit(4); }
    unsigned char *p = malloc(n ? n : 1);
    if (!p) { perror("malloc"); exit(2); }
    read_all(p, n);
    if (type == WSPH_ERROR) {
        rd_t e = { p, n, 0, 0 };
        char text[4097];
        uint32_t code = get_u32(&e); get_text(&e, text, sizeof text);
        fprintf(stderr, "server error %u: %s\n", code, text);
        exit(3);
    }
    if (type != expect_type || rseq != seq) {
        fprintf(stderr, "protocol: expected type %u seq %u, got type %u seq %u\n", expect_type, seq, type, rseq);
        exit(4);
    }
    *len = n;
    return p;
}

static int connect_to(const char *host, const char *port) {
    struct addrinfo hints = {0}, *res, *ai;
    hints.ai_family = AF_UNSPEC; hints.ai_socktype = SOCK_STREAM;
    int rc = getaddrinfo(host, port, &hints, &res);
    if (rc) { fprintf(stderr, "%s:%s: %s\n", host, port, gai_strerror(rc)); exit(2); }
    int fd = -1;
    for (ai = res; ai; ai = ai->ai_next) {
        fd = socket(ai->ai_family, ai->ai_socktype, ai->ai_protocol);
        if (fd < 0) continue;
        if (connect(fd, ai->ai_addr, ai->ai_addrlen) == 0) break;
        close(fd); fd = -1;
    }
    freeaddrinfo(res);
    if (fd < 0) { fprintf(stderr, "cannot connect to %s:%s\n", host, port); exit(2); }
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    struct timeval tv = { READ_TIMEOUT_S, 0 };
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    return fd;
}

/* ---------- linear (Airy) wave, z up from still water ---------- */
static double wavenumber(double omega, double g, double d) {
    double k = omega * omega / g;                     /* deep-water start */
    for (int i = 0; i < 100; i++) {                   /* Newton on w^2 = g k tanh(k d) */
        double t = tanh(k * d), f = g * k * t - omega * omega;
        double df = g * t + g * k * d * (1.0 - t * t);
        double dk = f / df; k -= dk;
        if (fabs(dk) < 1e-14 * k) break;
    }
    return k;
}

int main(int argc, char **argv) {
    if (argc != 5 && argc != 8) {
        fprintf(stderr, "usage: %s HOST PORT RUN_ID N_WINDOWS [H T WINDOW]\n", argv[0]);
        return 2;
    }
    int n_windows = atoi(argv[4]);
    double H = argc == 8 ? atof(argv[5]) : 0.05, T = argc == 8 ? atof(argv[6]) : 1.0;
    double window = argc == 8 ? atof(argv[7]) : 0.0;
    sock = connect_to(argv[1], argv[2]);

    /* HELLO: capabilities 0, no scene check (32 zero bytes), run id, client name */
    buf_t pl = {0}, out = {0};
    unsigned char zero_hash[32] = {0};
    put_u32(&pl, 0); put_bytes(&pl, zero_hash, 32); put_text(&pl, argv[3]); put_text(&pl, "wsph_client.c 1.0");
    send_frame(WSPH_HELLO, &pl, &out); write_all(&out);

    size_t n; unsigned char *p = recv_frame(WSPH_WELCOME, &n);
    rd_t r = { p, n, 0, 0 };
    get_u32(&r); r.pos += 32;                          /* capabilities, scene hash */
    double g = get_f64(&r), depth = get_f64(&r), swl = get_f64(&r), z_ref = get_f64(&r);
    double t = get_f64(&r), t_end = get_f64(&r), dt_sph = get_f64(&r), window_max = get_f64(&r);
    double idle = get_f64(&r);
    uint32_t N = get_u32(&r), G = get_u32(&r), max_payload = get_u32(&r);
    char run_id[4097], server[4097];
    get_text(&r, run_id, sizeof run_id); get_text(&r, server, sizeof server);
    if (r.bad || r.pos != n) { fprintf(stderr, "protocol: malformed WELCOME\n"); return 4; }
    free(p);
    fprintf(stderr, "WELCOME run %s from %s: g=%g depth=%g swl=%g z_ref=%g t=[%g,%g] dt_sph=%g "
            "window_max=%g idle=%g N=%u G=%u max_payload=%u\n", run_id, server, g, depth, swl, z_ref,
            t, t_end, dt_sph, window_max, idle, N, G, max_payload);
    if (window <= 0.0 || window > window_max) window = window_max;

    /* GETNODES -> NODES: node x, z (up from still water), side; gauge x */
    double *x = calloc(N + 1, 8), *z = calloc(N + 1, 8), *gx = calloc(G + 1, 8);
    double *u = calloc(N + 1, 8), *w = calloc(N + 1, 8), *eta = calloc(N + 1, 8);
    double *geta = calloc(G + 1, 8), *gu = calloc(G + 1, 8), *gw = calloc(G + 1, 8);
    uint32_t *side = calloc(N + 1, 4), *wet = calloc(G + 1, 4);
    if (!x || !z || !gx || !u || !w || !eta || !geta || !gu || !gw || !side || !wet) { perror("calloc"); return 2; }
    out.len = 0; send_frame(WSPH_GETNODES, NULL, &out); write_all(&out);
    p = recv_frame(WSPH_NODES, &n);
    r = (rd_t){ p, n, 0, 0 };
    get_f64_array(&r, x, N); get_f64_array(&r, z, N); get_u32_array(&r, side, N); get_f64_array(&r, gx, G);
    if (r.bad || r.pos != n) { fprintf(stderr, "protocol: malformed NODES\n"); return 4; }
    free(p);

    double omega = 2.0 * 3.14159265358979323846 / T, k = wavenumber(omega, g, depth), a = H / 2.0;
    for (int iw = 0; iw < n_windows && t < t_end; iw++) {
        double t1 = t + window < t_end ? t + window : t_end;
        for (uint32_t i = 0; i < N; i++) {          /* values at the window end t1 */
            double phase = k * x[i] - omega * t1;
            double zc = z[i] < 0.0 ? z[i] : 0.0;    /* no extrapolation above still water */
            u[i] = a * omega * cosh(k * (zc + depth)) / sinh(k * depth) * cos(phase);
            w[i] = a * omega * sinh(k * (zc + depth)) / sinh(k * depth) * sin(phase);
            eta[i] = a * cos(phase);
        }
        pl.len = 0; put_f64(&pl, t); put_f64(&pl, t1);
        put_f64_array(&pl, u, N); put_f64_array(&pl, w, N); put_f64_array(&pl, eta, N);
        out.len = 0;
        send_frame(WSPH_SET, &pl, &out);
        send_frame(WSPH_SOLVE, NULL, &out);         /* one write per window */
        write_all(&out);
        p = recv_frame(WSPH_RESULT, &n);
        r = (rd_t){ p, n, 0, 0 };
        double tr = get_f64(&r); uint32_t steps = get_u32(&r);
        get_f64_array(&r, geta, G); get_u32_array(&r, wet, G); get_f64_array(&r, gu, G); get_f64_array(&r, gw, G);
        if (r.bad || r.pos != n) { fprintf(stderr, "protocol: malformed RESULT\n"); return 4; }
        free(p);
        printf("RESULT %.17g %u", tr, steps);
        for (uint32_t j = 0; j < G; j++) {
            if (wet[j]) printf(" %.17g", geta[j]); else printf(" dry");
        }
        printf("\n");
        fflush(stdout);
        t = tr;
    }

    pl.len = 0; put_text(&pl, "done");
    out.len = 0; send_frame(WSPH_BYE, &pl, &out); write_all(&out);
    p = recv_frame(WSPH_BYE, &n); free(p);
    close(sock);
    return 0;
}

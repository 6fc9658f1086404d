/*
 * specdesign's forwarding DISCON: the Bladed interface of a controller that runs in Python.
 *
 * Each call sends the swap array to a Python process over a local (AF_UNIX) stream socket and
 * writes back the pitch and torque it answers. The Python side is specdesign.export.forward
 * (ForwardServer); the parameter file (accINFILE) is written by specdesign.export.forwarded:
 *
 *   specdesign-forward 1
 *   socket <path of the server's socket>        (no blanks or '#'; at most 107 bytes)
 *   timeout <s>                                  (connect, send and reply: never a hang)
 *   specdesign-discon 2 ... end                  (discon.c's format: limits, torque law)
 *
 * The embedded specdesign-discon part is read by discon.c's own reader and runs through
 * discon.c's own control_step (this file includes discon.c, its DISCON renamed): the generator
 * torque comes from the exported library's torque law, and the pitch command answered by Python
 * is clamped to the same pitch limits and rate limit the exported library applies to its own.
 * The embedded pitch bank is a zero controller; its command is not used.
 *
 * discon.c is included as it is, not edited: its bytes are the digest of every exported library
 * (specdesign.export.library) and campaign stores fingerprint that library, so the few lines of
 * its DISCON this file needs again (reading accINFILE's name, writing the outputs) are repeated
 * below rather than moved into a function there.
 *
 * The exchange, in the host's byte order (both ends on one machine), per call:
 *   request: uint32 magic 0x57464453, uint32 n = FORWARD_RECORDS, n float32: avrSWAP(1..n)
 *   reply:   uint32 magic 0x57464453, int32 code, uint32 size, then size bytes:
 *            code 0: two float64, the pitch command (rad) and the generator torque on the rotor
 *                    shaft (N m; NaN: the library's torque law);
 *            code 1: the Python side's error message (UTF-8), which fails the call.
 * Status 0 connects first; status -1 sends its request, reads the reply and closes. Any failure
 * (no server, a closed connection, a timeout, a malformed reply, a Python error) sets aviFAIL = -1
 * with a message naming the socket and the cause, and closes the connection.
 */
#define DISCON specdesign_exported_discon /* discon.c's entry point, renamed: this file's DISCON is below */
#include "discon.c"
#undef DISCON

#include <stdint.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/un.h>
#include <unistd.h>

#define FORWARD_NAME "specdesign-forward"
#define FORWARD_VERSION 1
#define FORWARD_MAGIC 0x57464453u
/* records sent: R_v43 = 165, every record ServoDyn v5.0.0 fills before the logging channels */
#define FORWARD_RECORDS 165
#define MAX_REPLY 65536

typedef struct {
    int fd;
    char socket[108];
    double timeout;
    double prev; /* the last command (rad), for the rate limit */
    long calls;
} Forward;

static Forward fw = {-1, {0}, 0.0, 0.0, 0};

static void disconnect(void)
{
    if (fw.fd >= 0)
        close(fw.fd);
    fw.fd = -1;
}

/* Parse the forward header, then discon.c's parameters (0, or -1 with the message in r->msg). */
static int parse_forward(Controller *c, Reader *r)
{
    char what[256];
    double v;
    if (!next_token(r) || strcmp(r->tok, FORWARD_NAME) != 0)
        return fail(r, r->tok_line, "not a specdesign forwarding parameter file: its first word must be '"
                                    FORWARD_NAME "' (write it with specdesign.export.forwarded)");
    if (number(r, "version", &v))
        return -1;
    if (v != FORWARD_VERSION) {
        snprintf(what, sizeof what, "forwarding format version %.17g, this library reads version %d", v,
                 FORWARD_VERSION);
        return fail(r, r->tok_line, what);
    }
    if (key(r, "socket"))
        return -1;
    if (!next_token(r))
        return fail(r, r->tok_line, "the file ends where the socket's path is expected");
    if (strlen(r->tok) >= sizeof fw.socket)
        return fail(r, r->tok_line, "the socket's path is longer than 107 bytes (AF_UNIX): put it in a shorter folder");
    snprintf(fw.socket, sizeof fw.socket, "%s", r->tok);
    if (numbers(r, "timeout", &fw.timeout, 1))
        return -1;
    if (!(fw.timeout > 0 && fw.timeout < 1e6))
        return fail(r, r->tok_line, "timeout must be in (0, 1e6) s");
    return parse(c, r);
}

static int load_forward(Controller *c, const char *path, char *msg, size_t msg_size)
{
    Reader r = {path, NULL, NULL, 1, msg, msg_size, {0}, 1};
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(msg, msg_size, "specdesign forward DISCON: cannot open the parameter file '%s': %s", path,
                 strerror(errno));
        return -1;
    }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    r.text = malloc(size > 0 ? (size_t)size + 1 : 1);
    size_t got = r.text && size > 0 ? fread(r.text, 1, (size_t)size, f) : 0;
    fclose(f);
    if (!r.text) {
        snprintf(msg, msg_size, "specdesign forward DISCON: %s: out of memory", path);
        return -1;
    }
    r.text[got] = 0;
    r.p = r.text;
    release(c);
    memset(c, 0, sizeof *c);
    int rc = parse_forward(c, &r);
    free(r.text);
    if (rc)
        release(c);
    return rc;
}

/* "specdesign forward DISCON: socket <path>: <cause>" into msg; always -1. */
static int link_fail(char *msg, size_t size, const char *cause)
{
    snprintf(msg, size, "specdesign forward DISCON: socket %s: %s", fw.socket, cause);
    disconnect();
    return -1;
}

static int connect_server(char *msg, size_t size)
{
    char cause[512];
    struct sockaddr_un addr;
    disconnect();
    fw.fd = socket(AF_UNIX, SOCK_STREAM, 0);
    if (fw.fd < 0) {
        snprintf(cause, sizeof cause, "cannot create a socket: %s", strerror(errno));
        return link_fail(msg, size, cause);
    }
    struct timeval tv;
    tv.tv_sec = (time_t)fw.timeout;
    tv.tv_usec = (suseconds_t)((fw.timeout - (double)tv.tv_sec) * 1e6);
    setsockopt(fw.fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(fw.fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
#ifdef SO_NOSIGPIPE
    int one = 1;
    setsockopt(fw.fd, SOL_SOCKET, SO_NOSIGPIPE, &one, sizeof one);
#endif
    memset(&addr, 0, sizeof addr);
    addr.sun_family = AF_UNIX;
    memcpy(addr.sun_path, fw.socket, strlen(fw.socket));
    if (connect(fw.fd, (struct sockaddr *)&addr, sizeof addr) != 0) {
        snprintf(cause, sizeof cause,
                 "cannot connect: %s (no Python server listening there: start specdesign.export.ForwardServer "
                 "before the simulation)", strerror(errno));
        return link_fail(msg, size, cause);
    }
    return 0;
}

#ifndef MSG_NOSIGNAL
#define MSG_NOSIGNAL 0 /* SO_NOSIGPIPE above instead */
#endif

static int send_all(const void *buf, size_t n, char *msg, size_t size)
{
    const char *p = buf;
    char cause[256];
    while (n) {
        ssize_t k = send(fw.fd, p, n, MSG_NOSIGNAL);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            snprintf(cause, sizeof cause, "cannot send the swap array: %s",
                     errno == EAGAIN || errno == EWOULDBLOCK ? "timed out" : strerror(errno));
            return link_fail(msg, size, cause);
        }
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

static int recv_all(void *buf, size_t n, char *msg, size_t size)
{
    char *p = buf, cause[256];
    while (n) {
        ssize_t k = recv(fw.fd, p, n, 0);
        if (k < 0 && errno == EINTR)
            continue;
        if (k == 0)
            return link_fail(msg, size, "the Python server closed the connection before replying");
        if (k < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK)
                snprintf(cause, sizeof cause, "no reply within the timeout of %g s (the Python controller is too "
                         "slow or stuck; raise timeout in specdesign.export.forwarded)", fw.timeout);
            else
                snprintf(cause, sizeof cause, "cannot read the reply: %s", strerror(errno));
            return link_fail(msg, size, cause);
        }
        p += k;
        n -= (size_t)k;
    }
    return 0;
}

/* One exchange: avrSWAP out, (pitch rad, rotor torque N m) back. */
static int exchange(const float *avrSWAP, double *pitch, double *torque, char *msg, size_t size)
{
    unsigned char req[8 + 4 * FORWARD_RECORDS];
    uint32_t head[2] = {FORWARD_MAGIC, FORWARD_RECORDS};
    memcpy(req, head, 8);
    memcpy(req + 8, avrSWAP, 4 * FORWARD_RECORDS);
    if (send_all(req, sizeof req, msg, size))
        return -1;
    uint32_t rep[3];
    if (recv_all(rep, sizeof rep, msg, size))
        return -1;
    char cause[1024];
    int32_t code;
    memcpy(&code, rep + 1, 4);
    if (rep[0] != FORWARD_MAGIC || (code == 0 && rep[2] != 16) || (code != 0 && code != 1) || rep[2] > MAX_REPLY) {
        snprintf(cause, sizeof cause, "malformed reply (magic 0x%08x, code %d, %u bytes): not a specdesign "
                 "ForwardServer", (unsigned)rep[0], (int)code, (unsigned)rep[2]);
        return link_fail(msg, size, cause);
    }
    char *body = malloc(rep[2] + 1);
    if (!body)
        return link_fail(msg, size, "out of memory");
    if (recv_all(body, rep[2], msg, size)) {
        free(body);
        return -1;
    }
    if (code == 1) {
        body[rep[2]] = 0;
        snprintf(cause, sizeof cause, "the Python controller failed: %s", body);
        free(body);
        return link_fail(msg, size, cause);
    }
    memcpy(pitch, body, 8);
    memcpy(torque, body + 8, 8);
    free(body);
    if (!isfinite(*pitch)) {
        snprintf(cause, sizeof cause, "malformed reply: pitch command %g", *pitch);
        return link_fail(msg, size, cause);
    }
    return 0;
}

EXPORT void DISCON(float *avrSWAP, int *aviFAIL, const char *accINFILE, char *avcOUTNAME, char *avcMSG)
{
    (void)avcOUTNAME;
    int status = (int)lrintf(avrSWAP[0]);
    char msg[1024];
    double pitch, torque, own;
    *aviFAIL = 0;
    if (status == -1) { /* the end of the run: the server is told, the connection closed, the state freed */
        int rc = fw.fd >= 0 ? exchange(avrSWAP, &pitch, &torque, msg, sizeof msg) : 0;
        disconnect();
        release(&ctl);
        *aviFAIL = rc ? -1 : 0;
        message(avcMSG, avrSWAP, rc ? msg : "");
        return;
    }
    if (status == 0) {
        char path[4097];
        int n = (int)avrSWAP[49]; /* avrSWAP(50): characters of accINFILE, its NUL included */
        if (n <= 0 || n > 4097)
            n = 4097;
        int i = 0;
        for (; i < n - 1 && accINFILE[i]; i++)
            path[i] = accINFILE[i];
        path[i] = 0;
        while (i > 0 && (path[i - 1] == ' ' || path[i - 1] == '\t'))
            path[--i] = 0;
        if (load_forward(&ctl, path, msg, sizeof msg)) {
            *aviFAIL = -1;
            message(avcMSG, avrSWAP, msg);
            return;
        }
        if (fabs(avrSWAP[2] - ctl.dt) > 1e-6 * ctl.dt) {
            snprintf(msg, sizeof msg,
                     "specdesign forward DISCON: %s: written for dt = %.9g s but called every %.6g s (avrSWAP(3), "
                     "ServoDyn's DLL_DT): write it again with dt = DLL_DT", path, ctl.dt, (double)avrSWAP[2]);
            release(&ctl);
            *aviFAIL = -1;
            message(avcMSG, avrSWAP, msg);
            return;
        }
        if (connect_server(msg, sizeof msg)) {
            release(&ctl);
            *aviFAIL = -1;
            message(avcMSG, avrSWAP, msg);
            return;
        }
        start(&ctl, avrSWAP[3], (double)avrSWAP[22] * ctl.gear);
        fw.calls = 0;
        ctl.ready = 1;
    } else if (!ctl.ready || fw.fd < 0) {
        *aviFAIL = -1;
        message(avcMSG, avrSWAP, "specdesign forward DISCON: called before its initialisation (avrSWAP(1) = 0) "
                                 "or after a failure");
        return;
    }
    /* the exported library's step with its zero pitch bank: its torque law (and its states) */
    (void)control_step(&ctl, avrSWAP[19] / ctl.gear, avrSWAP[14], avrSWAP[3], avrSWAP[52], &own);
    if (exchange(avrSWAP, &pitch, &torque, msg, sizeof msg)) {
        release(&ctl);
        *aviFAIL = -1;
        message(avcMSG, avrSWAP, msg);
        return;
    }
    /* the exported library's limits: the pitch range, then the command's rate limit */
    pitch = fmin(fmax(pitch, ctl.cmd_lo), ctl.cmd_hi);
    if (fw.calls > 0 && isfinite(ctl.rate_lim))
        pitch = fmin(fmax(pitch, fw.prev - ctl.rate_lim * ctl.dt), fw.prev + ctl.rate_lim * ctl.dt);
    fw.prev = pitch;
    fw.calls++;
    if (isnan(torque))
        torque = own;
    avrSWAP[44] = (float)pitch; /* 45: collective pitch */
    for (int k = 41; k < 44; k++) /* 42-44: the same per blade (read when avrSWAP(28) = 1) */
        avrSWAP[k] = (float)pitch;
    avrSWAP[46] = (float)(torque / ctl.gear); /* 47: generator torque, generator side */
    avrSWAP[34] = 1.0f;                      /* 35: generator contactor on */
    avrSWAP[35] = 0.0f;                      /* 36: shaft brake off */
    avrSWAP[40] = 0.0f;                      /* 41: yaw torque */
    avrSWAP[47] = 0.0f;                      /* 48: yaw rate */
    avrSWAP[54] = 0.0f;                      /* 55: no pitch override */
    avrSWAP[55] = 0.0f;                      /* 56: no torque override */
    avrSWAP[64] = 0.0f;                      /* 65: no logging channels */
    avrSWAP[101] = 0.0f;                     /* 102: yaw control flag */
    message(avcMSG, avrSWAP, "");
}

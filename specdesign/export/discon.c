/*
 * specdesign's exported pitch and torque controller behind the Bladed interface (DISCON).
 *
 * One source, compiled once by specdesign.export (cc -O2 -shared -fPIC), serves every design:
 * the design is the parameter file named by accINFILE ("specdesign-discon 2" format, written
 * by specdesign.export.export_discon and described in docs/export.md), read at the
 * initialisation call. The controller is the one specdesign.simulate's compiled loop runs
 * (specdesign/simulate/kernels.py, _run_one): the same discrete matrices (Tustin at the
 * controller's sample time, from specdesign.controller.scheduled.controller_bank), the same order of
 * operations, the same anti-windup (integrator clamp for PI-like locals, conditional
 * integration of the integrator and slow modes otherwise, ROSCO's clamps in the gains form),
 * the same scheduling filter and interpolation, and the same ROSCO torque law
 * (specdesign/rosco/torque.py, torque_step). Its state lives in one struct per loaded library.
 *
 * The swap entries read, as OpenFAST v5.0.0's ServoDyn fills them
 * (modules/servodyn/src/BladedInterface.f90, Fill_avrSWAP; 1-based Bladed records):
 *   dll_data%avrSWAP( 1) = dll_data%SimStatus                  status: 0 init, 1 step, -1 finish
 *   dll_data%avrSWAP( 2) = REAL(t, SiKi)                       time (s)
 *   dll_data%avrSWAP( 3) = dll_data%DLL_DT                     communication interval (s)
 *   dll_data%avrSWAP( 4) = u%BlPitch(1)                        blade-1 pitch (rad)
 *   dll_data%avrSWAP(15) = dll_data%ElecPwr_prev               electrical power (W)
 *   dll_data%avrSWAP(20) = u%HSS_Spd                           generator speed (rad/s)
 *   dll_data%avrSWAP(28) = dll_data%Ptch_Cntrl                 0 collective, 1 individual
 *   dll_data%avrSWAP(49) = ErrMsgSz + 1                        size of avcMSG
 *   dll_data%avrSWAP(50) = LEN_TRIM(dll_data%DLL_InFile) +1    characters of accINFILE (with its NUL)
 *   dll_data%avrSWAP(53) = u%YawBrTAxp                         tower-top fore-aft acceleration (m/s^2)
 * and the ones written back (Retrieve_avrSWAP):
 *   dll_data%BlPitchCom(:)   = dll_data%avrSWAP(45)            collective pitch command (rad)
 *   dll_data%BlPitchCom(K) = dll_data%avrSWAP( 41 + K )        the same per blade when avrSWAP(28) = 1
 *   dll_data%GenTrq     = dll_data%avrSWAP(47)                 generator torque (N m, generator side)
 *   dll_data%GenState  = NINT( dll_data%avrSWAP(35) )          contactor: 1 (main generator on)
 *   dll_data%ShaftBrakeStatusBinaryFlag = NINT(dll_data%avrSWAP(36))   0: brake off
 *   dll_data%YawRateCom = dll_data%avrSWAP(48)                 yaw rate: 0
 *   IF ( NINT( dll_data%avrSWAP(55) ) /=  0 ) ... (pitch override), avrSWAP(56) (torque override): 0
 *   p%NumOuts_DLL = NINT( m%dll_data%avrSWAP(65) )             logging channels: 0
 *   if (dll_data%avrSWAP(102)==4) ... elseif (dll_data%avrSWAP(102)==0)   yaw control flag: 0
 * The array holds R + 2*DLL_NumTrq - 1 + MaxLoggingChannels records, R = R_v43 = 165 and
 * MaxLoggingChannels = 300 (STATIC_DLL_LOAD aside), so every record written here exists.
 * ServoDyn calls status 0 once at initialisation (GetBladedLoggingChannels, t = 0), then 1 from
 * t = 0 every DLL_DT, and -1 at the end (BladedInterface_End).
 *
 * Speeds and torques inside are on the rotor (low-speed) shaft, as in the workbench: the
 * generator speed is divided by the file's gearbox ratio, the torque command divided by it.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FORMAT_NAME "specdesign-discon"
#define FORMAT_VERSION 2
#define MAX_DIM 4096

/* layout of the ROSCO torque law's parameters and states: specdesign/rosco/torque.py */
enum { T_MODE, T_K, T_KP, T_KI, T_MIN_SPEED, T_VS_REF, T_PC_REF, T_RATED_TQ, T_MAX_TQ, T_AR_SAT, T_MIN_TQ,
       T_MAX_RATE, T_RATED_POWER, T_GEN_EFF, T_FILT_TYPE, T_FILT_CORNER, T_FILT_DAMP, T_REF_CORNER, T_SS_MODE,
       T_SS_VS, T_SS_PC, T_SS_CORNER, T_PC_SWITCH, T_PITCH_MIN, T_CONST_POWER, TORQUE_PARAMS };
enum { S_WF, S_WF2, S_U1, S_U2, S_REF, S_REF_U, S_SSF, S_SS_U, S_IAR, S_IBR, S_AR, S_BR, S_STATE, S_TQ, S_PLAST };
#define TORQUE_STATES 16

enum { TQ_CONSTANT = 0, TQ_POWER = 1, TQ_ROSCO = 2, TQ_ROSCO_POWER = 3 };

typedef struct {
    int ready;
    /* parameters */
    double dt, gear, omega_ref, cmd_lo, cmd_hi, rate_lim;
    int torque_mode;
    double rated_torque, max_torque, rated_power, gen_eff, sf_corner, sf_damp;
    double tq[TORQUE_PARAMS];
    int nsf;
    double sfilt[5];
    double atd_hp;
    int K, nc;
    double *sched, *A, *B, *C, *D, *R;
    int *Ns;
    int pi_on, nf;
    double *kp, *ki, *Af, *Bf, *Cf, Df, lim[2];
    /* states */
    double *xc, *xn, *uk, *iq, *inc, *dslow, *xf, *xfn;
    double beta0, e_prev, integ, ef_prev, bcmd, bf, fu1, fu2, fy1, fy2;
    double tst[TORQUE_STATES];
    double pw[4]; /* speed filter of the constant-power law: y1, y2, u1, u2 */
    double a_prev, a_hp, vel; /* tower-top velocity from the acceleration */
    int qs;
    long step;
} Controller;

static Controller ctl;

static void release(Controller *c)
{
    double **arrays[] = {&c->sched, &c->A, &c->B, &c->C, &c->D, &c->R, &c->kp, &c->ki, &c->Af, &c->Bf, &c->Cf,
                         &c->xc, &c->xn, &c->uk, &c->iq, &c->inc, &c->dslow, &c->xf, &c->xfn};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++) {
        free(*arrays[i]);
        *arrays[i] = NULL;
    }
    free(c->Ns);
    c->Ns = NULL;
    c->ready = 0;
}

/* ------------------------------------------------------------------------------ reader */
typedef struct {
    const char *path;
    char *text, *p;
    int line;
    char *msg;
    size_t msg_size;
    char tok[128];
    int tok_line;
} Reader;

static int fail(Reader *r, int line, const char *what)
{
    snprintf(r->msg, r->msg_size, "specdesign DISCON: %s:%d: %s", r->path, line, what);
    return -1;
}

/* The next whitespace-separated token (comments from '#' to the end of the line skipped). */
static int next_token(Reader *r)
{
    for (;;) {
        while (*r->p == ' ' || *r->p == '\t' || *r->p == '\r' || *r->p == '\n') {
            if (*r->p == '\n')
                r->line++;
            r->p++;
        }
        if (*r->p == '#') {
            while (*r->p && *r->p != '\n')
                r->p++;
            continue;
        }
        break;
    }
    r->tok_line = r->line;
    if (!*r->p) {
        r->tok[0] = 0;
        return 0;
    }
    size_t n = 0;
    while (*r->p && *r->p != ' ' && *r->p != '\t' && *r->p != '\r' && *r->p != '\n' && *r->p != '#') {
        if (n + 1 < sizeof r->tok)
            r->tok[n++] = *r->p;
        r->p++;
    }
    r->tok[n] = 0;
    return 1;
}

static int key(Reader *r, const char *name)
{
    char what[256];
    if (!next_token(r)) {
        snprintf(what, sizeof what, "the file ends where '%s' is expected", name);
        return fail(r, r->tok_line, what);
    }
    if (strcmp(r->tok, name) != 0) {
        snprintf(what, sizeof what, "expected '%s', found '%.100s'", name, r->tok);
        return fail(r, r->tok_line, what);
    }
    return 0;
}

static int number(Reader *r, const char *name, double *out)
{
    char what[320];
    if (!next_token(r)) {
        snprintf(what, sizeof what, "the file ends where a number for '%s' is expected", name);
        return fail(r, r->tok_line, what);
    }
    char *end;
    errno = 0;
    double v = strtod(r->tok, &end);
    if (end == r->tok || *end || (errno == ERANGE && fabs(v) > 1.0) || isnan(v)) {
        snprintf(what, sizeof what, "'%.100s' is not a number (for '%s')", r->tok, name);
        return fail(r, r->tok_line, what);
    }
    *out = v;
    return 0;
}

static int numbers(Reader *r, const char *name, double *out, int n)
{
    if (key(r, name))
        return -1;
    for (int i = 0; i < n; i++)
        if (number(r, name, out + i))
            return -1;
    return 0;
}

static int integer(Reader *r, const char *name, int lo, int hi, int *out)
{
    double v;
    char what[256];
    if (key(r, name) || number(r, name, &v))
        return -1;
    if (v != floor(v) || v < lo || v > hi) {
        snprintf(what, sizeof what, "'%s' must be a whole number in [%d, %d], got %.17g", name, lo, hi, v);
        return fail(r, r->tok_line, what);
    }
    *out = (int)v;
    return 0;
}

static double *zeros(size_t n) { return calloc(n ? n : 1, sizeof(double)); }

static int parse(Controller *c, Reader *r)
{
    char what[256];
    double v;
    int version;
    if (!next_token(r) || strcmp(r->tok, FORMAT_NAME) != 0)
        return fail(r, r->tok_line, "not a specdesign DISCON parameter file: its first word must be '" FORMAT_NAME "'");
    if (number(r, "version", &v))
        return -1;
    version = (int)v;
    if (v != version || version != FORMAT_VERSION) {
        snprintf(what, sizeof what, "format version %.17g, this library reads version %d: export the design again",
                 v, FORMAT_VERSION);
        return fail(r, r->tok_line, what);
    }
    if (numbers(r, "dt", &c->dt, 1) || numbers(r, "gearbox_ratio", &c->gear, 1) ||
        numbers(r, "rated_speed", &c->omega_ref, 1) || numbers(r, "pitch_limits", &c->cmd_lo, 1) ||
        number(r, "pitch_limits", &c->cmd_hi) || numbers(r, "pitch_rate_limit", &c->rate_lim, 1))
        return -1;
    if (!(c->dt > 0) || !(c->gear > 0) || !(c->omega_ref > 0) || !(c->cmd_lo < c->cmd_hi) || !(c->rate_lim > 0))
        return fail(r, r->tok_line, "dt, gearbox_ratio, rated_speed and pitch_rate_limit must be positive and "
                                    "pitch_limits increasing");
    if (integer(r, "torque_mode", 0, 3, &c->torque_mode) || numbers(r, "rated_torque", &c->rated_torque, 1) ||
        numbers(r, "max_torque", &c->max_torque, 1) || numbers(r, "rated_power", &c->rated_power, 1) ||
        numbers(r, "generator_efficiency", &c->gen_eff, 1) || numbers(r, "speed_filter", &c->sf_corner, 1) ||
        number(r, "speed_filter", &c->sf_damp) || numbers(r, "torque_law", c->tq, TORQUE_PARAMS))
        return -1;
    if (c->torque_mode == TQ_POWER && !(c->rated_power > 0 && c->gen_eff > 0 && c->sf_corner > 0 && c->sf_damp > 0))
        return fail(r, r->tok_line, "torque_mode 1 (constant power) needs positive rated_power, generator_efficiency "
                                    "and speed_filter");
    if (c->torque_mode >= TQ_ROSCO && !(c->tq[T_MODE] == 1 || c->tq[T_MODE] == 3 || c->tq[T_MODE] == 4))
        return fail(r, r->tok_line, "torque_mode 2 and 3 need a torque_law whose first entry (VS_ControlMode) is 1, 3 "
                                    "or 4");
    if (c->torque_mode == TQ_ROSCO_POWER && !(c->tq[T_RATED_POWER] > 0 && c->tq[T_GEN_EFF] > 0))
        return fail(r, r->tok_line, "torque_mode 3 (constant power) needs the torque_law's rated power and efficiency");
    if (c->torque_mode >= TQ_ROSCO && (c->tq[T_CONST_POWER] != 0.0) != (c->torque_mode == TQ_ROSCO_POWER))
        return fail(r, r->tok_line, "torque_law's last entry (VS_ConstPower) must be 1 with torque_mode 3 and 0 with "
                                    "torque_mode 2");
    if (integer(r, "schedule_filter", 1, 5, &c->nsf))
        return -1;
    if (c->nsf != 1 && c->nsf != 5)
        return fail(r, r->tok_line, "schedule_filter has 1 (first order) or 5 (second order) coefficients");
    for (int i = 0; i < c->nsf; i++)
        if (number(r, "schedule_filter", c->sfilt + i))
            return -1;
    if (numbers(r, "atd_highpass", &c->atd_hp, 1))
        return -1;
    if (!(c->atd_hp >= 0))
        return fail(r, r->tok_line, "atd_highpass must be >= 0 rad/s");
    if (integer(r, "locals", 1, MAX_DIM, &c->K) || integer(r, "states", 1, MAX_DIM, &c->nc))
        return -1;
    int K = c->K, nc = c->nc;
    c->sched = zeros(K);
    c->A = zeros((size_t)K * nc * nc);
    c->B = zeros((size_t)K * nc * 2);
    c->C = zeros((size_t)K * nc);
    c->D = zeros((size_t)K * 2);
    c->R = zeros(K);
    c->Ns = calloc(K, sizeof(int));
    c->xc = zeros((size_t)K * nc);
    c->xn = zeros((size_t)K * nc);
    c->uk = zeros(K);
    c->iq = zeros(K);
    c->inc = zeros(K);
    c->dslow = zeros(K);
    if (!c->sched || !c->A || !c->B || !c->C || !c->D || !c->R || !c->Ns || !c->xc || !c->xn || !c->uk || !c->iq ||
        !c->inc || !c->dslow)
        return fail(r, r->tok_line, "out of memory");
    if (numbers(r, "schedule_pitch", c->sched, K))
        return -1;
    for (int q = 1; q < K; q++)
        if (!(c->sched[q] > c->sched[q - 1]))
            return fail(r, r->tok_line, "schedule_pitch must be strictly increasing");
    for (int q = 0; q < K; q++) {
        int idx;
        if (integer(r, "local", 0, K - 1, &idx))
            return -1;
        if (idx != q) {
            snprintf(what, sizeof what, "local %d where local %d is expected", idx, q);
            return fail(r, r->tok_line, what);
        }
        if (numbers(r, "integrator_gain", c->R + q, 1) || integer(r, "slow_states", 0, nc, c->Ns + q) ||
            numbers(r, "A", c->A + (size_t)q * nc * nc, nc * nc) || numbers(r, "B", c->B + (size_t)q * nc * 2, nc * 2) ||
            numbers(r, "C", c->C + (size_t)q * nc, nc) || numbers(r, "D", c->D + (size_t)q * 2, 2))
            return -1;
    }
    if (integer(r, "pi", 0, 1, &c->pi_on))
        return -1;
    if (c->pi_on) {
        if (integer(r, "pi_filter_states", 0, MAX_DIM, &c->nf))
            return -1;
        int nf = c->nf;
        c->kp = zeros(K);
        c->ki = zeros(K);
        c->Af = zeros((size_t)nf * nf);
        c->Bf = zeros(nf);
        c->Cf = zeros(nf);
        c->xf = zeros(nf);
        c->xfn = zeros(nf);
        if (!c->kp || !c->ki || !c->Af || !c->Bf || !c->Cf || !c->xf || !c->xfn)
            return fail(r, r->tok_line, "out of memory");
        if (numbers(r, "pi_kp", c->kp, K) || numbers(r, "pi_ki", c->ki, K) || numbers(r, "pi_A", c->Af, nf * nf) ||
            numbers(r, "pi_B", c->Bf, nf) || numbers(r, "pi_C", c->Cf, nf) || numbers(r, "pi_D", &c->Df, 1) ||
            numbers(r, "pi_limits", c->lim, 2))
            return -1;
    }
    if (key(r, "end"))
        return -1;
    if (next_token(r)) {
        snprintf(what, sizeof what, "'%.100s' after 'end'", r->tok);
        return fail(r, r->tok_line, what);
    }
    return 0;
}

/* Read the parameter file into ctl (0, or -1 with the message in msg). */
static int load(Controller *c, const char *path, char *msg, size_t msg_size)
{
    Reader r = {path, NULL, NULL, 1, msg, msg_size, {0}, 1};
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(msg, msg_size, "specdesign DISCON: cannot open the parameter file '%s': %s", path, strerror(errno));
        return -1;
    }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    r.text = malloc(size > 0 ? (size_t)size + 1 : 1);
    if (!r.text) {
        fclose(f);
        snprintf(msg, msg_size, "specdesign DISCON: %s: out of memory", path);
        return -1;
    }
    size_t got = size > 0 ? fread(r.text, 1, (size_t)size, f) : 0;
    fclose(f);
    r.text[got] = 0;
    r.p = r.text;
    release(c);
    memset(c, 0, sizeof *c);
    int rc = parse(c, &r);
    free(r.text);
    if (rc)
        release(c);
    return rc;
}

/* ------------------------------------------------------------------------------ torque law */
/* ROSCO's LPFilter (Tustin), reset to its input on the first call: torque.py, rosco_lpf1 */
static double lpf1(double *st, int iy, int iu, double u, double corner, double dt, int first)
{
    if (first) {
        st[iy] = u;
        st[iu] = u;
    }
    double a1 = 2.0 + corner * dt, a0 = corner * dt - 2.0, b = corner * dt;
    double y = (-a0 * st[iy] + b * u + b * st[iu]) / a1;
    st[iy] = y;
    st[iu] = u;
    return y;
}

/* ROSCO's PIController: torque.py, _pi */
static double pi_ctl(double err, double kp, double ki, double lo, double hi, double dt, double i0, double *st, int idx,
                     int first)
{
    if (first) {
        st[idx] = i0;
        return i0;
    }
    st[idx] = fmin(fmax(st[idx] + dt * ki * err, lo), hi);
    return fmin(fmax(kp * err + st[idx], lo), hi);
}

/* ROSCO's second-order low-pass (Tustin), the form of torque.py's speed filter; st = y1, y2, u1, u2 */
static double lpf2(double *st, double u, double corner, double damp, double dt, int first)
{
    if (first)
        st[0] = st[1] = st[2] = st[3] = u;
    double h2 = dt * dt * corner * corner;
    double a2 = h2 + 4.0 + 4.0 * damp * corner * dt, a1 = 2.0 * h2 - 8.0, a0 = h2 + 4.0 - 4.0 * damp * corner * dt;
    double y = (h2 * u + 2.0 * h2 * st[2] + h2 * st[3] - a1 * st[0] - a0 * st[1]) / a2;
    st[3] = st[2];
    st[2] = u;
    st[1] = st[0];
    st[0] = y;
    return y;
}

/* One step of ROSCO's torque controller: a line-by-line port of torque.py, torque_step. With
 * const_power, ROSCO's VS_ConstPower = 1 (Controllers.f90, VariableSpeedControl): region 3 holds
 * P/(eta*wf), and the torque ceiling is min(P/(eta*wf), VS_MaxTq) instead of VS_RtTq. */
static double torque_step(const double *tq, double *st, double omega, double power, double pitch, double dt, int first,
                          int const_power, double *pc_ref_out)
{
    int mode = (int)tq[T_MODE];
    double c = tq[T_FILT_CORNER], wf;
    if (first) {
        st[S_WF] = omega;
        st[S_WF2] = omega;
        st[S_U1] = omega;
        st[S_U2] = omega;
        st[S_SSF] = 0.0;
        st[S_PLAST] = power;
    }
    if (tq[T_FILT_TYPE] == 1.0) {
        wf = lpf1(st, S_WF, S_U1, omega, c, dt, 0);
    } else {
        double h2 = dt * dt * c * c, z = tq[T_FILT_DAMP];
        double a2 = h2 + 4.0 + 4.0 * z * c * dt, a1 = 2.0 * h2 - 8.0, a0 = h2 + 4.0 - 4.0 * z * c * dt;
        wf = (h2 * omega + 2.0 * h2 * st[S_U1] + h2 * st[S_U2] - a1 * st[S_WF] - a0 * st[S_WF2]) / a2;
        st[S_U2] = st[S_U1];
        st[S_U1] = omega;
        st[S_WF2] = st[S_WF];
        st[S_WF] = wf;
    }
    double ssf = st[S_SSF];
    double pc_ref = ssf < 0.0 ? tq[T_PC_REF] - ssf : tq[T_PC_REF];
    double k = tq[T_K], ref;
    if (mode == 3)
        ref = pow(fmax(power, 0.0) / tq[T_GEN_EFF] / k, 1.0 / 3.0);
    else if (mode == 4)
        ref = sqrt(fmax(st[S_TQ], 0.0) / k);
    else
        ref = tq[T_VS_REF];
    if (tq[T_REF_CORNER] > 0.0)
        ref = lpf1(st, S_REF, S_REF_U, ref, tq[T_REF_CORNER], dt, first);
    double vs_ref = fmin(fmax(ref, tq[T_MIN_SPEED]), tq[T_VS_REF]);
    if (ssf > 0.0)
        vs_ref -= ssf;
    vs_ref = fmax(vs_ref, tq[T_MIN_SPEED]);
    double err = vs_ref - wf, err_br = tq[T_MIN_SPEED] - wf;
    double min_om = k * pow(tq[T_MIN_SPEED], 2), max_om = k * pow(tq[T_VS_REF], 2);
    double rgn3 = tq[T_PITCH_MIN] + tq[T_PC_SWITCH];
    int state;
    if (first)
        state = pitch >= rgn3 ? 4 : 2;
    else if (pitch >= rgn3)
        state = 4;
    else if (st[S_AR] >= max_om * 1.01)
        state = 3;
    else if (wf < tq[T_VS_REF] && st[S_BR] >= min_om)
        state = 2;
    else if (st[S_BR] < min_om)
        state = 1;
    else
        state = 0;
    st[S_STATE] = state;
    if (tq[T_SS_MODE] != 0.0) {
        double d = ((pitch - tq[T_PITCH_MIN]) / 0.524 * tq[T_SS_VS] -
                    (tq[T_RATED_POWER] - st[S_PLAST]) / tq[T_RATED_POWER] * tq[T_SS_PC]) * tq[T_PC_REF];
        st[S_SSF] = lpf1(st, S_SSF, S_SS_U, d, tq[T_SS_CORNER], dt, first);
    }
    double last = st[S_TQ], t;
    double pwr_tq = tq[T_RATED_POWER] / tq[T_GEN_EFF] / wf;
    double ceiling = const_power ? fmin(pwr_tq, tq[T_MAX_TQ]) : tq[T_RATED_TQ];
    if (mode == 1) {
        double ar = pi_ctl(err, tq[T_KP], tq[T_KI], max_om, tq[T_AR_SAT], dt, max_om, st, S_IAR, first);
        double br = pi_ctl(err_br, tq[T_KP], tq[T_KI], tq[T_MIN_TQ], min_om, dt, min_om, st, S_IBR, first);
        st[S_AR] = ar;
        st[S_BR] = br;
        if (state == 1)
            t = br;
        else if (state == 2)
            t = k * wf * wf;
        else if (state == 3)
            t = ar;
        else if (state == 4)
            t = const_power ? pwr_tq : tq[T_RATED_TQ];
        else
            t = last;
    } else {
        t = pi_ctl(err, tq[T_KP], tq[T_KI], tq[T_MIN_TQ], ceiling, dt, last, st, S_IAR, first);
    }
    t = fmin(fmax(t, tq[T_MIN_TQ]), fmin(tq[T_MAX_TQ], ceiling));
    if (!first) {
        double rr = tq[T_MAX_RATE] * dt;
        t = fmin(fmax(t, last - rr), last + rr);
    }
    st[S_TQ] = t;
    st[S_PLAST] = power;
    *pc_ref_out = pc_ref;
    return fmax(t, 0.0);
}

/* ------------------------------------------------------------------------------ controller step */
/* At the initialisation: the operating point is the measured pitch and torque, every state at rest
 * there (the simulator's trim start, so the first command is bumpless). */
static void start(Controller *c, double pitch, double torque)
{
    c->beta0 = pitch;
    c->bcmd = pitch;
    c->bf = c->fu1 = c->fu2 = c->fy1 = c->fy2 = pitch;
    c->e_prev = c->integ = c->ef_prev = 0.0;
    c->qs = 0;
    memset(c->tst, 0, sizeof c->tst);
    c->tst[S_TQ] = torque;
    c->vel = c->a_hp = c->a_prev = 0.0;
    c->step = 0;
}

/* One controller step; omega rotor speed (rad/s), power (W), pitch measured (rad), acc tower-top
 * fore-aft acceleration (m/s^2). Returns the pitch command (rad); *torque the rotor-side torque (N m).
 * The pitch part is specdesign/simulate/kernels.py, _run_one, statement by statement. */
static double control_step(Controller *c, double omega, double power, double pitch, double acc, double *torque)
{
    const int K = c->K, nc = c->nc, nf = c->nf, first = c->step == 0;
    const double dt = c->dt;
    double wref = c->omega_ref, e, v;
    if (c->torque_mode == TQ_ROSCO || c->torque_mode == TQ_ROSCO_POWER) {
        *torque = torque_step(c->tq, c->tst, omega, power, pitch, dt, first, c->torque_mode == TQ_ROSCO_POWER, &wref);
    } else if (c->torque_mode == TQ_POWER) {
        double wf = lpf2(c->pw, omega, c->sf_corner, c->sf_damp, dt, first);
        *torque = fmin(c->rated_power / (c->gen_eff * wf), c->max_torque);
    } else {
        *torque = c->rated_torque;
    }
    e = -(omega - wref);
    /* tower-top velocity from the acceleration: high-passed, s/(s + w), then a leaky integral,
     * 1/(s + w), both by Tustin (w = atd_highpass; with w = 0 the trapezoid integral of the
     * acceleration). The velocity starts at 0 (the trim's) and the high-pass passes the first
     * acceleration (a transient at the start, not a bias: a bias decays from it over 1/w) */
    if (first) {
        c->a_prev = acc;
        c->a_hp = acc;
        c->vel = 0.0;
    } else {
        double w = c->atd_hp, g = (2.0 - w * dt) / (2.0 + w * dt);
        double hp = g * c->a_hp + 2.0 / (2.0 + w * dt) * (acc - c->a_prev);
        c->vel = g * c->vel + dt / (2.0 + w * dt) * (hp + c->a_hp);
        c->a_hp = hp;
        c->a_prev = acc;
    }
    v = -c->vel;
    int slow = 0;
    const double ilo = c->cmd_lo - c->beta0, ihi = c->cmd_hi - c->beta0;
    for (int q = 0; q < K; q++) {
        const double *A = c->A + (size_t)q * nc * nc, *B = c->B + (size_t)q * nc * 2, *C = c->C + (size_t)q * nc,
                     *D = c->D + (size_t)q * 2;
        double *xc = c->xc + (size_t)q * nc, *xn = c->xn + (size_t)q * nc;
        double s = D[0] * e + D[1] * v;
        for (int i = 0; i < nc; i++)
            s += C[i] * xc[i];
        for (int i = 0; i < nc; i++) {
            double a = B[2 * i] * e + B[2 * i + 1] * v;
            for (int m = 0; m < nc; m++)
                a += A[i * nc + m] * xc[m];
            xn[i] = a;
        }
        if (c->R[q] != 0.0) {
            if (c->Ns[q] == 0) {
                c->iq[q] = fmin(fmax(c->iq[q] + c->R[q] * 0.5 * dt * (e + c->e_prev), ilo), ihi);
            } else { /* tentatively; undone below if the command saturates this way */
                slow = 1;
                c->inc[q] = c->R[q] * 0.5 * dt * (e + c->e_prev);
                c->iq[q] += c->inc[q];
                double d = c->inc[q];
                for (int i = 0; i < c->Ns[q]; i++)
                    d += C[i] * (xn[i] - xc[i]);
                c->dslow[q] = d;
            }
            s += c->iq[q];
        }
        c->uk[q] = s;
    }
    c->e_prev = e;
    /* piecewise-linear weights in the filtered pitch, clamped at the ends */
    int q = 0;
    double f = 0.0, u;
    if (K == 1 || c->bf <= c->sched[0]) {
        q = 0;
    } else if (c->bf >= c->sched[K - 1]) {
        q = K - 1;
    } else {
        q = c->qs;
        while (q > 0 && c->sched[q] >= c->bf)
            q--;
        while (c->sched[q + 1] < c->bf)
            q++;
        c->qs = q;
        f = (c->bf - c->sched[q]) / (c->sched[q + 1] - c->sched[q]);
    }
    u = f == 0.0 ? c->uk[q] : (1.0 - f) * c->uk[q] + f * c->uk[q + 1];
    if (slow) {
        double over = c->beta0 + u - c->cmd_hi;
        if (over <= 0.0)
            over = fmin(c->beta0 + u - c->cmd_lo, 0.0);
        if (over != 0.0) { /* saturated: freeze the slow parts that push further past the limit */
            for (int r = 0; r < K; r++) {
                if (c->Ns[r] > 0 && c->R[r] != 0.0 && c->dslow[r] * over > 0.0) {
                    c->iq[r] -= c->inc[r];
                    c->uk[r] -= c->inc[r];
                    for (int i = 0; i < c->Ns[r]; i++)
                        c->xn[(size_t)r * nc + i] = c->xc[(size_t)r * nc + i];
                }
            }
            u = f == 0.0 ? c->uk[q] : (1.0 - f) * c->uk[q] + f * c->uk[q + 1];
        }
    }
    memcpy(c->xc, c->xn, sizeof(double) * (size_t)K * nc);
    if (c->pi_on) { /* ROSCO's form: one filtered error, gains interpolated in the filtered pitch */
        double ef = c->Df * e;
        for (int i = 0; i < nf; i++)
            ef += c->Cf[i] * c->xf[i];
        for (int i = 0; i < nf; i++) {
            double a = c->Bf[i] * e;
            for (int m = 0; m < nf; m++)
                a += c->Af[i * nf + m] * c->xf[m];
            c->xfn[i] = a;
        }
        for (int i = 0; i < nf; i++)
            c->xf[i] = c->xfn[i];
        double kpv, kiv;
        if (f == 0.0) {
            kpv = c->kp[q];
            kiv = c->ki[q];
        } else {
            kpv = (1.0 - f) * c->kp[q] + f * c->kp[q + 1];
            kiv = (1.0 - f) * c->ki[q] + f * c->ki[q + 1];
        }
        c->integ += kiv * 0.5 * dt * (ef + c->ef_prev);
        c->ef_prev = ef;
        double lo = c->lim[0] - c->beta0, hi = c->lim[1] - c->beta0;
        c->integ = fmin(fmax(c->integ, lo), hi);
        u += fmin(fmax(kpv * ef + c->integ, lo), hi);
    }
    double prev = c->bcmd;
    c->bcmd = fmin(fmax(c->beta0 + u, c->cmd_lo), c->cmd_hi);
    if (!first && isfinite(c->rate_lim)) /* the command's rate limit (inf in the workbench's own runs) */
        c->bcmd = fmin(fmax(c->bcmd, prev - c->rate_lim * dt), prev + c->rate_lim * dt);
    if (c->nsf == 1) {
        c->bf += c->sfilt[0] * (c->bcmd - c->bf);
    } else {
        c->bf = c->sfilt[0] * c->bcmd + c->sfilt[1] * c->fu1 + c->sfilt[2] * c->fu2 - c->sfilt[3] * c->fy1 -
                c->sfilt[4] * c->fy2;
        c->fu2 = c->fu1;
        c->fu1 = c->bcmd;
        c->fy2 = c->fy1;
        c->fy1 = c->bf;
    }
    c->step++;
    return c->bcmd;
}

/* ------------------------------------------------------------------------------ the interface */
static void message(char *avcMSG, const float *avrSWAP, const char *text)
{
    int size = (int)avrSWAP[48]; /* avrSWAP(49): characters avcMSG holds, its NUL included */
    if (size <= 0 || size > 4096)
        size = 1024;
    snprintf(avcMSG, (size_t)size, "%s", text);
}

#if defined(_WIN32)
#define EXPORT __declspec(dllexport)
#else
#define EXPORT __attribute__((visibility("default")))
#endif

EXPORT void DISCON(float *avrSWAP, int *aviFAIL, const char *accINFILE, char *avcOUTNAME, char *avcMSG)
{
    (void)avcOUTNAME;
    int status = (int)lrintf(avrSWAP[0]);
    char msg[1024];
    *aviFAIL = 0;
    if (status == -1) { /* the end of the run: nothing to write, the state is freed */
        release(&ctl);
        message(avcMSG, avrSWAP, "");
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
        /* ServoDyn passes the name as written in its input: trailing blanks are not part of it */
        while (i > 0 && (path[i - 1] == ' ' || path[i - 1] == '\t'))
            path[--i] = 0;
        if (load(&ctl, path, msg, sizeof msg)) {
            *aviFAIL = -1;
            message(avcMSG, avrSWAP, msg);
            return;
        }
        if (fabs(avrSWAP[2] - ctl.dt) > 1e-6 * ctl.dt) {
            snprintf(msg, sizeof msg,
                     "specdesign DISCON: %s: the design is discrete at dt = %.9g s but the controller is called every "
                     "%.6g s (avrSWAP(3), ServoDyn's DLL_DT): export it again with dt = DLL_DT",
                     path, ctl.dt, (double)avrSWAP[2]);
            release(&ctl);
            *aviFAIL = -1;
            message(avcMSG, avrSWAP, msg);
            return;
        }
        start(&ctl, avrSWAP[3], (double)avrSWAP[22] * ctl.gear);
        ctl.ready = 1;
    } else if (!ctl.ready) {
        *aviFAIL = -1;
        message(avcMSG, avrSWAP, "specdesign DISCON: called before its initialisation (avrSWAP(1) = 0)");
        return;
    }
    double torque;
    double pitch = control_step(&ctl, avrSWAP[19] / ctl.gear, avrSWAP[14], avrSWAP[3], avrSWAP[52], &torque);
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

/* The glue the thesis does not publish, written as a user would: one burst's words to the attitude.
   The timer ISR (isr.c) reads a burst every 4 ms; the published conversion gives deg/s and g; the
   rates, in rad/s, are the samples at t, t+T/2 and t+T, two bursts per 8 ms update, the last sample of
   an update being the first of the next (the profile's schedule = "half-step"); Wnbb is each sample
   less the navigation frame's rate (navigation.c), then updateQ; the Euler angles come from T by the
   thesis' tables 2-1 (roll) and 2-2 (yaw), pitch = -asin(T31); then one navigation step with the
   latest specific force. */
#include <math.h>

#include "reference.h"

/* Constants as one literal each (a user's #defines): pi/180 and g as the emulator's firmware model
   holds them (firmware.accel_g_m_s2), the "-> 0" threshold of the tables (firmware.euler_zero_eps). */
#define DEG_TO_RAD 0.017453292519943295
#define G_M_S2 9.80665
#define ZERO_EPS 1e-6
#define HALF_PI 1.5707963267948966
#define PI 3.141592653589793
#define THREE_HALF_PI 4.71238898038469
#define TWO_PI 6.283185307179586

double pitch, roll, yaw;
double w_ib[3][3]; /* the update's rate samples, rad/s */
double f_b[3];      /* the latest specific force, m/s^2 */
Uint32 updates;
static Uint16 samples;

/* Table 2-1: roll from T32 / T33. */
static double roll_table(double t32, double t33)
{
    double principal;
    if (fabs(t33) < ZERO_EPS)
        return t32 >= 0 ? HALF_PI : -HALF_PI;
    principal = atan(t32 / t33);
    if (t33 > 0)
        return principal;
    else if (t32 >= 0)
        return principal + PI;
    else
        return principal - PI;
}

/* Table 2-2: yaw from T21 / T11, in [0, 2 pi). */
static double yaw_table(double t21, double t11)
{
    double principal;
    if (fabs(t11) < ZERO_EPS)
        return t21 >= 0 ? HALF_PI : THREE_HALF_PI;
    principal = atan(t21 / t11);
    if (t11 > 0) {
        if (t21 >= 0)
            return principal;
        else
            return principal + TWO_PI;
    }
    return principal + PI;
}

static void update_euler(void)
{
    double s = T[2][0];
    /* asin's domain: rounding can take |T31| a little past 1 near +-90 deg of pitch. */
    if (s > 1)
        s = 1;
    else if (s < -1)
        s = -1;
    pitch = -asin(s);
    roll = roll_table(T[2][1], T[2][2]);
    yaw = yaw_table(T[1][0], T[0][0]);
}

void reference_process_burst(const Uint16 rdata[15])
{
    int i;
    convert_data(rdata);
    for (i = 0; i < 3; i++) {
        w_ib[samples][i] = a[i] * DEG_TO_RAD;
        f_b[i] = a[i + 3] * G_M_S2;
    }
    samples++;
    if (samples == 3) {
        body_rates(w_ib);
        updateQ();
        update_euler();
        navigate(f_b);
        updates++;
        for (i = 0; i < 3; i++)
            w_ib[0][i] = w_ib[2][i];
        samples = 1;
    }
}

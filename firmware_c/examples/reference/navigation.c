/* Glue the thesis describes (section 4.5) but does not publish: the earth and transport rates that
   turn the gyros' w_ib into the body rates Wnbb the RK4 update takes, and the navigation (velocity and
   position) that the transport rate needs. Written as a user would, in the operation order of the
   emulator's firmware model (reference-design.md, "Earth model and navigation"): navigation frame x
   east, y north, z up; first-order radii; WGS-84 normal gravity with a free-air correction; one explicit
   Euler step per update period from the state at the start of the step. */
#include <math.h>

#include "reference.h"

/* The site and the earth model of the reference profile ([navigation]). */
#define EARTH_RADIUS 6378137.0
#define FLATTENING 0.0033528131778969143
#define E2 0.00669438499958795        /* f (2 - f) */
#define EARTH_RATE 7.292115e-5
#define GAMMA_E 9.7803253359
#define SOMIGLIANA_K 0.00193185265241
#define LATITUDE_RAD 0.7127924665144842  /* 40.84 deg */
#define LONGITUDE_RAD 1.9504054391036634 /* 111.75 deg */
#define HEIGHT_M 1050.0

double lat = LATITUDE_RAD, lon = LONGITUDE_RAD, height = HEIGHT_M;
double vel[3]; /* east, north, up, m/s */

/* The earth quantities of one step. */
static double w_ie[3], w_en[3], sin_lat, cos_lat, rn_h, re_h;

static void earth_rates(void)
{
    double s2, rn, re, tan_lat;
    sin_lat = sin(lat);
    cos_lat = cos(lat);
    s2 = sin_lat * sin_lat;
    rn = EARTH_RADIUS * (1 - 2 * FLATTENING + 3 * FLATTENING * s2);
    re = EARTH_RADIUS * (1 + FLATTENING * s2);
    rn_h = rn + height;
    re_h = re + height;
    tan_lat = sin_lat / cos_lat;
    w_ie[0] = 0;
    w_ie[1] = EARTH_RATE * cos_lat;
    w_ie[2] = EARTH_RATE * sin_lat;
    w_en[0] = -(vel[1] / rn_h);
    w_en[1] = vel[0] / re_h;
    w_en[2] = (vel[0] * tan_lat) / re_h;
}

/* Wnbb[k] = w_ib[k] - C_n^b w_in^n, C_n^b = T transposed (T as of the last update). */
void body_rates(double w_ib[3][3])
{
    double w_in[3], proj;
    int i, k;
    earth_rates();
    for (i = 0; i < 3; i++)
        w_in[i] = w_ie[i] + w_en[i];
    for (k = 0; k < 3; k++)
        for (i = 0; i < 3; i++) {
            proj = T[0][i] * w_in[0] + T[1][i] * w_in[1] + T[2][i] * w_in[2];
            Wnbb[k][i] = w_ib[k][i] - proj;
        }
}

/* Normal gravity at the latitude's sine and a height, m/s^2. */
static double gravity(double s, double h)
{
    double s2 = s * s;
    double gamma = GAMMA_E * (1 + SOMIGLIANA_K * s2) / sqrt(1 - E2 * s2);
    return gamma * (1 - (2 * h) / EARTH_RADIUS);
}

/* One step of T1 seconds with the specific force f_b (m/s^2) and T = C_b^n. */
void navigate(const double f_b[3])
{
    double g, f_n[3], a[3], v[3], coriolis[3], gravity_n[3], lat_dot, lon_dot, v_dot;
    int i;
    earth_rates();
    g = gravity(sin_lat, height);
    for (i = 0; i < 3; i++) {
        f_n[i] = T[i][0] * f_b[0] + T[i][1] * f_b[1] + T[i][2] * f_b[2];
        a[i] = 2 * w_ie[i] + w_en[i];
        v[i] = vel[i];
    }
    coriolis[0] = a[1] * v[2] - a[2] * v[1];
    coriolis[1] = a[2] * v[0] - a[0] * v[2];
    coriolis[2] = a[0] * v[1] - a[1] * v[0];
    gravity_n[0] = 0;
    gravity_n[1] = 0;
    gravity_n[2] = -g;
    lat_dot = v[1] / rn_h;
    lon_dot = v[0] / (re_h * cos_lat);
    for (i = 0; i < 3; i++) {
        v_dot = f_n[i] - coriolis[i] + gravity_n[i];
        vel[i] = v[i] + v_dot * T1;
    }
    lat = lat + lat_dot * T1;
    lon = lon + lon_dot * T1;
    height = height + v[2] * T1;
}

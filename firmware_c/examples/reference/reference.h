/* The reference design's firmware (2014 thesis, F28335 + ADIS16407), as a user writes it against TI's
   DSP2833x headers: the published code (published.c: the data conversion of section 4.4.3 and the
   RK4 quaternion update of appendix 1, as printed) and the glue the thesis does not publish (glue.c:
   one burst's words to the attitude; navigation.c: the earth and transport rates, the navigation;
   isr.c: CPU timer 0, the burst read, main).

   The variables are the published code's: `double` as printed (32-bit under TI's COFF ABI: build with
   `sins-fw build-firmware --float c28x`; `--float host` gives the f64 reference). */
#ifndef REFERENCE_H
#define REFERENCE_H

#include "DSP2833x_Device.h"

/* Published globals (appendix 1). */
extern double Q[4];       /* attitude quaternion, body to navigation */
extern double T[3][3];    /* attitude matrix C_b^n */
extern double Wnbb[3][3]; /* body rates at t, t+T/2, t+T, rad/s */
extern double T1;         /* update period, s */

/* Published data conversion (section 4.4.3): the 14 valid bits of the six inertial words, then the
   range tests; a[0..2] in deg/s, a[3..5] in g (kept when a word is in neither range). */
extern Uint16 rdata1[6];
extern double a[6];
void convert_data(const Uint16 rdata[15]);

/* Published RK4 update, normalisation and attitude matrix (appendix 1). */
void updateQ(void);

/* Glue (navigation.c): the earth-rate and transport-rate correction, the navigation. */
extern double lat, lon, height, vel[3];
void body_rates(double w_ib[3][3]);
void navigate(const double f_b[3]);

/* Glue: the Euler angles (rad) of T by the thesis' tables 2-1 and 2-2, updated after each updateQ. */
extern double pitch, roll, yaw;
extern Uint32 updates;
void reference_process_burst(const Uint16 rdata[15]);

#endif

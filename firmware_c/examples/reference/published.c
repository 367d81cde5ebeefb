/* The published code of the reference design (2014 thesis), as printed: the data conversion of section
   4.4.3 (gyro and accelerometer words to deg/s and g) and appendix 1 (RK4 quaternion update,
   normalisation, attitude matrix). Only the printing's typesetting is undone (`update Q` is updateQ,
   `3.333e - 003` is 3.333e-003, the loop over the six words is written out around the printed
   bodies). The q2 derivative rows keep the printed `- Wnbb[k][0]*X[3]` (profile key
   firmware.quat_derivative = "published"). */
#include <math.h>

#include "reference.h"

double Q[4] = {1, 0, 0, 0};
double T[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
double Wnbb[3][3];
double T1 = 0.008;

Uint16 rdata1[6];
double a[6];

/* Section 4.4.3: keep each register's valid bits (14 for the gyros and accelerometers), then convert.
   rdata[0] answers the 0x4200 command, rdata[1] is SUPPLY_OUT, rdata[2..7] X/Y/Z GYRO_OUT, X/Y/Z
   ACCL_OUT. */
void convert_data(const Uint16 rdata[15])
{
    int i;
    for (i = 0; i < 6; i++)
        rdata1[i] = rdata[i + 2] & 0x3FFF;

    for (i = 0; i < 3; i++) {
        if ( ( rdata1[i] >= 0x0000 ) && ( rdata1[i] <= 0x1770 ) )
            { a[i] = rdata1[i] * 0.05; }
        else if ( ( rdata1[i] >= 0x2890 ) && ( rdata1[i] <= 0x3FFF ) )
            { rdata1[i] ^= 0x3FFF;
              rdata1[i] = rdata1[i] + 0x0001;
              a[i] = 0 - ( rdata1[i] * 0.05 ); }
    }
    for (i = 3; i < 6; i++) {
        if ( ( rdata1[i] >= 0x0000 ) && ( rdata1[i] <= 0x1519 ) )
            { a[i] = rdata1[i] * 3.333e-003; }
        else if ( ( rdata1[i] >= 0x2AE7 ) && ( rdata1[i] <= 0x3FFF ) )
            { rdata1[i] ^= 0x3FFF;
              rdata1[i] = rdata1[i] + 0x0001;
              a[i] = 0 - ( rdata1[i] * 3.333e-003 ); }
    }
}

void updateQ()
{
    double mo;

    double K1[4], K2[4], K3[4], K4[4];
    double A[4], B[4], C1[4];

    /* 四阶龙格库塔法解四元数微分方程 */
    K1[0] = ( -Wnbb[0][0]*Q[1] - Wnbb[0][1]*Q[2] - Wnbb[0][2]*Q[3] )/2;
    K1[1] = ( Wnbb[0][0]*Q[0] + Wnbb[0][2]*Q[2] - Wnbb[0][1]*Q[3] )/2;
    K1[2] = ( Wnbb[0][1]*Q[0] - Wnbb[0][2]*Q[1] - Wnbb[0][0]*Q[3] )/2;
    K1[3] = ( Wnbb[0][2]*Q[0] + Wnbb[0][1]*Q[1] - Wnbb[0][0]*Q[2] )/2;

    A[0] = Q[0] + K1[0]*T1/2;
    A[1] = Q[1] + K1[1]*T1/2;
    A[2] = Q[2] + K1[2]*T1/2;
    A[3] = Q[3] + K1[3]*T1/2;

    K2[0] = ( -Wnbb[1][0]*A[1] - Wnbb[1][1]*A[2] - Wnbb[1][2]*A[3] )/2;
    K2[1] = ( Wnbb[1][0]*A[0] + Wnbb[1][2]*A[2] - Wnbb[1][1]*A[3] )/2;
    K2[2] = ( Wnbb[1][1]*A[0] - Wnbb[1][2]*A[1] - Wnbb[1][0]*A[3] )/2;
    K2[3] = ( Wnbb[1][2]*A[0] + Wnbb[1][1]*A[1] - Wnbb[1][0]*A[2] )/2;

    B[0] = Q[0] + K2[0]*T1/2;
    B[1] = Q[1] + K2[1]*T1/2;
    B[2] = Q[2] + K2[2]*T1/2;
    B[3] = Q[3] + K2[3]*T1/2;

    K3[0] = ( -Wnbb[1][0]*B[1] - Wnbb[1][1]*B[2] - Wnbb[1][2]*B[3] )/2;
    K3[1] = ( Wnbb[1][0]*B[0] + Wnbb[1][2]*B[2] - Wnbb[1][1]*B[3] )/2;
    K3[2] = ( Wnbb[1][1]*B[0] - Wnbb[1][2]*B[1] - Wnbb[1][0]*B[3] )/2;
    K3[3] = ( Wnbb[1][2]*B[0] + Wnbb[1][1]*B[1] - Wnbb[1][0]*B[2])/2;

    C1[0] = Q[0] + K3[0]*T1;
    C1[1] = Q[1] + K3[1]*T1;
    C1[2] = Q[2] + K3[2]*T1;
    C1[3] = Q[3] + K3[3]*T1;

    K4[0] = ( -Wnbb[2][0]*C1[1] - Wnbb[2][1]*C1[2] - Wnbb[2][2]*C1[3] )/2;
    K4[1] = ( Wnbb[2][0]*C1[0] + Wnbb[2][2]*C1[2] - Wnbb[2][1]*C1[3] )/2;
    K4[2] = ( Wnbb[2][1]*C1[0] - Wnbb[2][2]*C1[1] - Wnbb[2][0]*C1[3] )/2;
    K4[3] = ( Wnbb[2][2]*C1[0] + Wnbb[2][1]*C1[1] - Wnbb[2][0]*C1[2] )/2;

    Q[0] = Q[0] + ( K1[0] + 2*K2[0] + 2*K3[0] + K4[0] )*T1/6;
    Q[1] = Q[1] + ( K1[1] + 2*K2[1] + 2*K3[1] + K4[1] )*T1/6;
    Q[2] = Q[2] + ( K1[2] + 2*K2[2] + 2*K3[2] + K4[2] )*T1/6;
    Q[3] = Q[3] + ( K1[3] + 2*K2[3] + 2*K3[3] + K4[3] )*T1/6;

    /* 归一化 */
    mo = sqrt( Q[0]*Q[0] + Q[1]*Q[1] + Q[2]*Q[2] + Q[3]*Q[3] );
    Q[0] = Q[0] / mo;
    Q[1] = Q[1] / mo;
    Q[2] = Q[2] / mo;
    Q[3] = Q[3] / mo;

    /* 更新姿态矩阵 */
    T[0][0] = Q[0]*Q[0] + Q[1]*Q[1] - Q[2]*Q[2] - Q[3]*Q[3];
    T[0][1] = ( Q[1]*Q[2] - Q[0]*Q[3] )*2;
    T[0][2] = ( Q[1]*Q[3] + Q[0]*Q[2] )*2;
    T[1][0] = ( Q[1]*Q[2] + Q[0]*Q[3] )*2;
    T[1][1] = Q[0]*Q[0] - Q[1]*Q[1] + Q[2]*Q[2] - Q[3]*Q[3];
    T[1][2] = ( Q[2]*Q[3] - Q[0]*Q[1] ) *2;
    T[2][0] = ( Q[1]*Q[3] - Q[0]*Q[2] ) *2;
    T[2][1] = ( Q[2]*Q[3] + Q[0]*Q[1] ) *2;
    T[2][2] = Q[0]*Q[0] - Q[1]*Q[1] - Q[2]*Q[2] + Q[3]*Q[3];
}

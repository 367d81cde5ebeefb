/* The geomagnetic–gyro board's acquisition (firmware_model/geomag.toml), written as a user would
   against TI's DSP2833x headers: CPU timer 0 interrupts every millisecond; the ISR converts the
   ADS8344's eight channels over SPI-A in 8-bit characters, one chip-select window per channel on
   GPIO57 (a GPIO output): the control byte (start bit, the channel's A2..A0, single-ended, PD1 PD0 =
   11: external clock, no power-down), then three read bytes; the code is the 16 bits after the null
   bit, (b1 << 16 | b2 << 8 | b3) >> 7 (ads8344.md). It then turns the codes into what the board's
   firmware works with: the gyro's rates (rad/s) compensated with the calibration table, the field
   (gauss) and the board temperature (degC). The constants are the profile's [geomag] presets and
   calibration (spin1200 on x, adxrs300 on y and z, the AMR magnetometer, VREF 5 V), one #define each.
   SPI-A is set up as the profile's [spi] InitSpi: mode 0 (CLKPOLARITY 0, CLK_PHASE 1), 8-bit
   characters, SPIBRR 15: 37.5 MHz / 16 = 2.34 MHz, below the part's 2.4 MHz DCLK. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

#define CHANNELS 8
#define TIMER_PERIOD_US 1000

#define VREF_V 5.0f
#define LSB_V (VREF_V / 65536.0f)
#define PI_F 3.14159265358979f
#define DEG_TO_RAD (PI_F / 180.0f)
/* The gyros: null V, V per deg/s (spin1200 on x; adxrs300 on y, z). */
#define GYRO_X_NULL_V 2.5f
#define GYRO_X_V_PER_DPS 0.0016f
#define GYRO_YZ_NULL_V 2.5f
#define GYRO_YZ_V_PER_DPS 0.005f
/* The magnetometer: null V, V per gauss. */
#define MAG_NULL_V 2.5f
#define MAG_V_PER_GAUSS 1.0f
/* The temperature sensor on CH6: 0.5 V + 10 mV/degC. */
#define TEMP_OFFSET_V 0.5f
#define TEMP_V_PER_C 0.01f

interrupt void cpu_timer0_isr(void);

/* The calibration table (geomag.calibration): bias deg/s, bias deg/s per degC, its reference
   temperature, scale-factor error, nonlinearity (fraction of full scale), full scale deg/s. */
static const float32 cal_bias_dps[3] = {0.0f, 0.0f, 0.0f};
static const float32 cal_temp_dps_per_c[3] = {0.02f, 0.01f, 0.01f};
static const float32 cal_ref_temp_c[3] = {25.0f, 25.0f, 25.0f};
static const float32 cal_scale_error[3] = {0.0f, 0.0f, 0.0f};
static const float32 cal_nonlinearity[3] = {0.001f, 0.001f, 0.001f};
static const float32 cal_full_scale_dps[3] = {1200.0f, 300.0f, 300.0f};

/* A2 A1 A0 of single-ended channel n (the data sheet's Table I: not the binary order). */
static const Uint16 channel_select[CHANNELS] = {0, 4, 1, 5, 2, 6, 3, 7};

Uint16 codes[CHANNELS]; /* the ADS8344's codes, CH0..CH7 */
float32 rate[3];        /* compensated rates, rad/s */
float32 field[3];       /* the field, gauss */
float32 temp_c;         /* the board temperature */
Uint32 conversions;     /* ISRs run */

/* The profile's InitSpi: SPICCR in reset with 8-bit characters, SPICTL, SPIBRR, SPICCR released,
   SPIPRI. */
static void InitSpi(void)
{
    SpiaRegs.SPICCR.all = 0x0007;  /* in reset, CLKPOLARITY = 0, SPICHAR = 7: 8-bit characters */
    SpiaRegs.SPICTL.all = 0x000F;  /* CLK_PHASE = 1 (mode 0), master, TALK, interrupt enable */
    SpiaRegs.SPIBRR = 15;          /* LSPCLK 37.5 MHz / 16 = 2.34 MHz */
    SpiaRegs.SPICCR.all = 0x0087;  /* out of reset */
    SpiaRegs.SPIPRI.all = 0x0020;  /* SOFT */
}

/* GPIO57, the ADC's chip select, a GPIO output, high. */
static void InitChipSelect(void)
{
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
    EALLOW;
    GpioCtrlRegs.GPBMUX2.bit.GPIO57 = 0;
    GpioCtrlRegs.GPBDIR.bit.GPIO57 = 1;
    EDIS;
}

/* One character: wait for room, send `a` (an 8-bit character goes out from SPITXBUF's top byte),
   wait for the received character, read it (its bits in SPIRXBUF's low byte). */
static Uint16 spi_xmit(Uint16 a)
{
    while (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1) { }
    SpiaRegs.SPITXBUF = a;
    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) { }
    return SpiaRegs.SPIRXBUF;
}

/* One conversion of single-ended channel `ch`, external clock. */
static Uint16 convert(Uint16 ch)
{
    Uint32 b1, b2, b3;
    Uint16 control = (Uint16)(0x80u | channel_select[ch] << 4 | 0x04u | 0x03u);
    GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1;
    spi_xmit((Uint16)(control << 8));
    b1 = spi_xmit(0) & 0xFFu;
    b2 = spi_xmit(0) & 0xFFu;
    b3 = spi_xmit(0) & 0xFFu;
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
    return (Uint16)(((b1 << 16) | (b2 << 8) | b3) >> 7);
}

static float32 volts(Uint16 code)
{
    return (float32)code * LSB_V;
}

/* The codes to rates, field and temperature; the gyro compensated as the calibration table says:
   less the bias and its temperature term, over (1 + scale error), then one pass of w = m - k m|m|
   with k = nonlinearity / ((1 + scale error) full scale) (in rad/s). */
static void decode(void)
{
    int i;
    float32 measured[3];
    temp_c = (volts(codes[6]) - TEMP_OFFSET_V) / TEMP_V_PER_C;
    measured[0] = (volts(codes[0]) - GYRO_X_NULL_V) / (GYRO_X_V_PER_DPS / DEG_TO_RAD);
    measured[1] = (volts(codes[1]) - GYRO_YZ_NULL_V) / (GYRO_YZ_V_PER_DPS / DEG_TO_RAD);
    measured[2] = (volts(codes[2]) - GYRO_YZ_NULL_V) / (GYRO_YZ_V_PER_DPS / DEG_TO_RAD);
    for (i = 0; i < 3; i++) {
        float32 unbiased = measured[i] - cal_bias_dps[i] * DEG_TO_RAD
                           - cal_temp_dps_per_c[i] * DEG_TO_RAD * (temp_c - cal_ref_temp_c[i]);
        float32 m = unbiased / (1.0f + cal_scale_error[i]);
        float32 k = cal_nonlinearity[i] / ((1.0f + cal_scale_error[i]) * cal_full_scale_dps[i] * DEG_TO_RAD);
        rate[i] = m - k * m * (m < 0 ? -m : m);
        field[i] = (volts(codes[3 + i]) - MAG_NULL_V) / MAG_V_PER_GAUSS;
    }
}

void main(void)
{
    InitSysCtrl();  /* 150 MHz; LSPCLK = SYSCLKOUT / 4 */
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();
    EALLOW;
    PieVectTable.TINT0 = &cpu_timer0_isr;
    EDIS;

    InitChipSelect();
    InitSpi();

    InitCpuTimers();
    ConfigCpuTimer(&CpuTimer0, 150, TIMER_PERIOD_US);
    CpuTimer0Regs.TCR.all = 0x4001;  /* TIE = 1, TSS = 0: start */

    IER |= M_INT1;
    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;  /* TINT0 */
    EINT;
    ERTM;
    for (;;) { }
}

/* Every tick: the eight channels in order, then the decode. */
interrupt void cpu_timer0_isr(void)
{
    Uint16 ch;
    for (ch = 0; ch < CHANNELS; ch++)
        codes[ch] = convert(ch);
    decode();
    conversions++;
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}

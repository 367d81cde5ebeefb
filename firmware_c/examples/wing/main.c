/* The wing-angle unit's acquisition (firmware_model/wing.toml), written as a user would against TI's
   DSP2833x headers: CPU timer 0 interrupts every 4 ms; the ISR reads one burst of the ADIS16362 over
   SPI-A with GPIO57 (a GPIO output) as the chip select: the burst command 0x3E00 (a read of
   GLOB_CMD's address), then eleven frames that bring SUPPLY_OUT, X/Y/ZGYRO_OUT, X/Y/ZACCL_OUT,
   X/Y/ZTEMP_OUT and AUX_ADC (adis16362.md, data sheet p. 11). It then decodes the six inertial words:
   the 14 valid bits as two's complement, times the LSB of the range SENS_AVG selects at power-on
   (0x0402: +-300 deg/s, 0.05 deg/s) and the accelerometers' 0.333 mg, in rad/s and m/s^2 (g =
   9.80665 m/s^2, the profile's firmware.accel_g_m_s2).
   SPI-A is set up as the profile's [spi] InitSpi: mode 3 (CLKPOLARITY 1, CLK_PHASE 0), 16-bit
   characters, SPIBRR 49: 37.5 MHz / 50 = 0.75 MHz, below the part's 1 MHz burst SCLK. */
#include "DSP2833x_Device.h"
#include "DSP2833x_Examples.h"

#define BURST_FRAMES 12  /* the command's frame and the eleven output words */
#define BURST_COMMAND 0x3E00
#define TIMER_PERIOD_US 4000
/* Inside a burst the part wants one SCLK period between frames (1.33 us at 0.75 MHz): the polled
   loop alone leaves about 1 us, so each frame is followed by a wait. */
#define BURST_STALL_US 1

#define PI_F 3.14159265358979f
#define GYRO_LSB_RAD_S (0.05f * PI_F / 180.0f)
#define ACCEL_LSB_M_S2 (0.333e-3f * 9.80665f)

interrupt void cpu_timer0_isr(void);

Uint16 words[BURST_FRAMES]; /* what each frame of the burst brought, the command's frame first */
float32 rate[3];            /* X/Y/ZGYRO_OUT, rad/s */
float32 accel[3];           /* X/Y/ZACCL_OUT, m/s^2 */
Uint32 bursts;              /* ISRs run */

/* The profile's InitSpi: SPICCR in reset, SPICTL, SPIBRR, SPICCR released, SPIPRI. */
static void InitSpi(void)
{
    SpiaRegs.SPICCR.all = 0x004F;  /* in reset, CLKPOLARITY = 1, 16-bit characters */
    SpiaRegs.SPICTL.all = 0x0007;  /* master, TALK, SPI interrupt enable; CLK_PHASE = 0: mode 3 */
    SpiaRegs.SPIBRR = 49;          /* LSPCLK 37.5 MHz / 50 = 0.75 MHz */
    SpiaRegs.SPICCR.all = 0x00CF;  /* out of reset */
    SpiaRegs.SPIPRI.all = 0x0020;  /* SOFT */
}

/* GPIO57, the part's chip select, a GPIO output, high. */
static void InitChipSelect(void)
{
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
    EALLOW;
    GpioCtrlRegs.GPBMUX2.bit.GPIO57 = 0;
    GpioCtrlRegs.GPBDIR.bit.GPIO57 = 1;
    EDIS;
}

static Uint16 spi_xmit(Uint16 a)
{
    while (SpiaRegs.SPISTS.bit.BUFFULL_FLAG == 1) { }
    SpiaRegs.SPITXBUF = a;
    while (SpiaRegs.SPISTS.bit.INT_FLAG != 1) { }
    return SpiaRegs.SPIRXBUF;
}

/* A 14-bit two's-complement output word's code. */
static int16 code14(Uint16 word)
{
    return (int16)(word << 2) >> 2;
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

/* One burst per tick, then the decode. */
interrupt void cpu_timer0_isr(void)
{
    Uint16 i;
    GpioDataRegs.GPBCLEAR.bit.GPIO57 = 1;
    for (i = 0; i < BURST_FRAMES; i++) {
        words[i] = spi_xmit(i == 0 ? BURST_COMMAND : 0x0000);
        DELAY_US(BURST_STALL_US);
    }
    GpioDataRegs.GPBSET.bit.GPIO57 = 1;
    for (i = 0; i < 3; i++) {
        rate[i] = code14(words[2 + i]) * GYRO_LSB_RAD_S;
        accel[i] = code14(words[5 + i]) * ACCEL_LSB_M_S2;
    }
    bursts++;
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}

/* CPU timer 0 every millisecond, its ISR the one this project's copy of DSP2833x_PieVect.c puts in
   PieVectTableInit (nothing here sets PieVectTable.TINT0): InitPieVectTable's copy must reach the
   emulated PIE for the ISR to run. `high` is 1 when the vectors past the first 64, read back from
   PieVectTable as whole pointers and as 32-bit words, are the table's. */
#include "DSP28x_Project.h"

extern const struct PIE_VECT_TABLE PieVectTableInit; /* DSP2833x_PieVect.c */

Uint16 ticks;   /* timer 0 interrupts taken */
Uint16 high;    /* the copied vectors read back as the table's */

interrupt void timer0_isr(void)
{
    ticks++;
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP1;
}

interrupt void spi_rx_isr(void)
{
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP6;
}

interrupt void luf_isr(void)
{
    PieCtrlRegs.PIEACK.all = PIEACK_GROUP12;
}

void main(void)
{
    const Uint32 *table = (const void *)&PieVectTableInit;
    const Uint32 *vectors = (const void *)&PieVectTable;

    InitSysCtrl();
    DINT;
    InitPieCtrl();
    IER = 0x0000;
    IFR = 0x0000;
    InitPieVectTable();

    high = PieVectTable.SPIRXINTA == &spi_rx_isr && PieVectTable.LUF == &luf_isr &&
           PieVectTable.ILLEGAL == &ILLEGAL_ISR && vectors[72] == table[72] && vectors[127] == table[127];

    InitCpuTimers();
#if (CPU_FRQ_150MHZ)
    ConfigCpuTimer(&CpuTimer0, 150, 1000);
#endif
    CpuTimer0Regs.TCR.all = 0x4001;
    IER |= M_INT1;
    PieCtrlRegs.PIEIER1.bit.INTx7 = 1;
    EINT;
    for (;;) {
    }
}

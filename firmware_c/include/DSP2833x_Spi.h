/* Replacement for TI's DSP2833x_Spi.h: SPI-A at 0x7040 (word offsets as in the F28335 reference
   manual; field names as in TI's header). */
#ifndef DSP2833x_SPI_H
#define DSP2833x_SPI_H

#include "sins_fw_reg.hpp"

#define SINS_SPIA 0x7040u

struct SPICCR_BITS {
    SinsField<SINS_SPIA + 0, 0, 4> SPICHAR;
    SinsField<SINS_SPIA + 0, 4, 1> SPILBK;
    SinsField<SINS_SPIA + 0, 6, 1> CLKPOLARITY;
    SinsField<SINS_SPIA + 0, 7, 1> SPISWRESET;
};
union SPICCR_REG {
    SinsReg16<SINS_SPIA + 0> all;
    struct SPICCR_BITS bit;
};

struct SPICTL_BITS {
    SinsField<SINS_SPIA + 1, 0, 1> SPIINTENA;
    SinsField<SINS_SPIA + 1, 1, 1> TALK;
    SinsField<SINS_SPIA + 1, 2, 1> MASTER_SLAVE;
    SinsField<SINS_SPIA + 1, 3, 1> CLK_PHASE;
    SinsField<SINS_SPIA + 1, 4, 1> OVERRUNINTENA;
};
union SPICTL_REG {
    SinsReg16<SINS_SPIA + 1> all;
    struct SPICTL_BITS bit;
};

struct SPISTS_BITS {
    SinsField<SINS_SPIA + 2, 5, 1> BUFFULL_FLAG;
    SinsField<SINS_SPIA + 2, 6, 1> INT_FLAG;
    SinsField<SINS_SPIA + 2, 7, 1> OVERRUN_FLAG;
};
union SPISTS_REG {
    SinsReg16<SINS_SPIA + 2> all;
    struct SPISTS_BITS bit;
};

struct SPIFFTX_BITS {
    SinsField<SINS_SPIA + 0xA, 0, 5> TXFFIL;
    SinsField<SINS_SPIA + 0xA, 5, 1> TXFFIENA;
    SinsField<SINS_SPIA + 0xA, 6, 1> TXFFINTCLR;
    SinsField<SINS_SPIA + 0xA, 7, 1> TXFFINT;
    SinsField<SINS_SPIA + 0xA, 8, 5> TXFFST;
    SinsField<SINS_SPIA + 0xA, 13, 1> TXFIFO;
    SinsField<SINS_SPIA + 0xA, 14, 1> SPIFFENA;
    SinsField<SINS_SPIA + 0xA, 15, 1> SPIRST;
};
union SPIFFTX_REG {
    SinsReg16<SINS_SPIA + 0xA> all;
    struct SPIFFTX_BITS bit;
};

struct SPIFFRX_BITS {
    SinsField<SINS_SPIA + 0xB, 0, 5> RXFFIL;
    SinsField<SINS_SPIA + 0xB, 5, 1> RXFFIENA;
    SinsField<SINS_SPIA + 0xB, 6, 1> RXFFINTCLR;
    SinsField<SINS_SPIA + 0xB, 7, 1> RXFFINT;
    SinsField<SINS_SPIA + 0xB, 8, 5> RXFFST;
    SinsField<SINS_SPIA + 0xB, 13, 1> RXFIFORESET;
    SinsField<SINS_SPIA + 0xB, 14, 1> RXFFOVFCLR;
    SinsField<SINS_SPIA + 0xB, 15, 1> RXFFOVF;
};
union SPIFFRX_REG {
    SinsReg16<SINS_SPIA + 0xB> all;
    struct SPIFFRX_BITS bit;
};

struct SPIFFCT_BITS {
    SinsField<SINS_SPIA + 0xC, 0, 8> TXDLY;
};
union SPIFFCT_REG {
    SinsReg16<SINS_SPIA + 0xC> all;
    struct SPIFFCT_BITS bit;
};

struct SPIPRI_BITS {
    SinsField<SINS_SPIA + 0xF, 4, 1> FREE;
    SinsField<SINS_SPIA + 0xF, 5, 1> SOFT;
    SinsField<SINS_SPIA + 0xF, 6, 1> PRIORITY;
};
union SPIPRI_REG {
    SinsReg16<SINS_SPIA + 0xF> all;
    struct SPIPRI_BITS bit;
};

struct SPI_REGS {
    union SPICCR_REG SPICCR;
    union SPICTL_REG SPICTL;
    union SPISTS_REG SPISTS;
    SinsReg16<SINS_SPIA + 4> SPIBRR;
    SinsReg16<SINS_SPIA + 6> SPIRXEMU;
    SinsReg16<SINS_SPIA + 7> SPIRXBUF;
    SinsReg16<SINS_SPIA + 8> SPITXBUF;
    SinsReg16<SINS_SPIA + 9> SPIDAT;
    union SPIFFTX_REG SPIFFTX;
    union SPIFFRX_REG SPIFFRX;
    union SPIFFCT_REG SPIFFCT;
    union SPIPRI_REG SPIPRI;
};

extern volatile struct SPI_REGS SpiaRegs;

#endif

/* Replacement for TI's DSP2833x_PieCtrl.h: the PIE control registers at 0x0CE0 (PIECTRL, PIEACK,
   PIEIER1…12, PIEIFR1…12; field names as in TI's header) and the PIEACK_GROUPx masks. */
#ifndef DSP2833x_PIE_CTRL_H
#define DSP2833x_PIE_CTRL_H

#include "sins_fw_reg.hpp"

#define SINS_PIE 0x0CE0u

struct PIECTRL_BITS {
    SinsField<SINS_PIE + 0, 0, 1> ENPIE;
    SinsField<SINS_PIE + 0, 1, 15> PIEVECT;
};
union PIECTRL_REG {
    SinsReg16<SINS_PIE + 0> all;
    struct PIECTRL_BITS bit;
};

struct PIEACK_BITS {
    SinsField<SINS_PIE + 1, 0, 1> ACK1;
    SinsField<SINS_PIE + 1, 1, 1> ACK2;
    SinsField<SINS_PIE + 1, 2, 1> ACK3;
    SinsField<SINS_PIE + 1, 3, 1> ACK4;
    SinsField<SINS_PIE + 1, 4, 1> ACK5;
    SinsField<SINS_PIE + 1, 5, 1> ACK6;
    SinsField<SINS_PIE + 1, 6, 1> ACK7;
    SinsField<SINS_PIE + 1, 7, 1> ACK8;
    SinsField<SINS_PIE + 1, 8, 1> ACK9;
    SinsField<SINS_PIE + 1, 9, 1> ACK10;
    SinsField<SINS_PIE + 1, 10, 1> ACK11;
    SinsField<SINS_PIE + 1, 11, 1> ACK12;
};
union PIEACK_REG {
    SinsReg16<SINS_PIE + 1> all;
    struct PIEACK_BITS bit;
};

/* PIEIERx and PIEIFRx of group G at word offset O (2 + 2(G−1) and one more). */
template <uint32_t A>
struct SINS_PIEX_BITS {
    SinsField<A, 0, 1> INTx1;
    SinsField<A, 1, 1> INTx2;
    SinsField<A, 2, 1> INTx3;
    SinsField<A, 3, 1> INTx4;
    SinsField<A, 4, 1> INTx5;
    SinsField<A, 5, 1> INTx6;
    SinsField<A, 6, 1> INTx7;
    SinsField<A, 7, 1> INTx8;
};
template <uint32_t A>
union SINS_PIEX_REG {
    SinsReg16<A> all;
    SINS_PIEX_BITS<A> bit;
};

struct PIE_CTRL_REGS {
    union PIECTRL_REG PIECTRL;
    union PIEACK_REG PIEACK;
    SINS_PIEX_REG<SINS_PIE + 0x02> PIEIER1;
    SINS_PIEX_REG<SINS_PIE + 0x03> PIEIFR1;
    SINS_PIEX_REG<SINS_PIE + 0x04> PIEIER2;
    SINS_PIEX_REG<SINS_PIE + 0x05> PIEIFR2;
    SINS_PIEX_REG<SINS_PIE + 0x06> PIEIER3;
    SINS_PIEX_REG<SINS_PIE + 0x07> PIEIFR3;
    SINS_PIEX_REG<SINS_PIE + 0x08> PIEIER4;
    SINS_PIEX_REG<SINS_PIE + 0x09> PIEIFR4;
    SINS_PIEX_REG<SINS_PIE + 0x0A> PIEIER5;
    SINS_PIEX_REG<SINS_PIE + 0x0B> PIEIFR5;
    SINS_PIEX_REG<SINS_PIE + 0x0C> PIEIER6;
    SINS_PIEX_REG<SINS_PIE + 0x0D> PIEIFR6;
    SINS_PIEX_REG<SINS_PIE + 0x0E> PIEIER7;
    SINS_PIEX_REG<SINS_PIE + 0x0F> PIEIFR7;
    SINS_PIEX_REG<SINS_PIE + 0x10> PIEIER8;
    SINS_PIEX_REG<SINS_PIE + 0x11> PIEIFR8;
    SINS_PIEX_REG<SINS_PIE + 0x12> PIEIER9;
    SINS_PIEX_REG<SINS_PIE + 0x13> PIEIFR9;
    SINS_PIEX_REG<SINS_PIE + 0x14> PIEIER10;
    SINS_PIEX_REG<SINS_PIE + 0x15> PIEIFR10;
    SINS_PIEX_REG<SINS_PIE + 0x16> PIEIER11;
    SINS_PIEX_REG<SINS_PIE + 0x17> PIEIFR11;
    SINS_PIEX_REG<SINS_PIE + 0x18> PIEIER12;
    SINS_PIEX_REG<SINS_PIE + 0x19> PIEIFR12;
};

extern volatile struct PIE_CTRL_REGS PieCtrlRegs;

#define PIEACK_GROUP1 0x0001
#define PIEACK_GROUP2 0x0002
#define PIEACK_GROUP3 0x0004
#define PIEACK_GROUP4 0x0008
#define PIEACK_GROUP5 0x0010
#define PIEACK_GROUP6 0x0020
#define PIEACK_GROUP7 0x0040
#define PIEACK_GROUP8 0x0080
#define PIEACK_GROUP9 0x0100
#define PIEACK_GROUP10 0x0200
#define PIEACK_GROUP11 0x0400
#define PIEACK_GROUP12 0x0800

#endif

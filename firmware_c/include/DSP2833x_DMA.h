/* Replacement for TI's DSP2833x_DMA.h in a host build: the DMA's registers (DmaRegs at 0x1000,
   EALLOW-protected; six channels of 0x20 words from 0x1020) with TI's layout and field names (F2833x DMA
   reference guide SPRUFB8). Not modelled: the registers read and write with their reset values (0) and
   the first use is reported once (`unmodelled_peripheral`); nothing is moved. */
#ifndef DSP2833x_DMA_H
#define DSP2833x_DMA_H

#ifdef __cplusplus
extern "C" {
#endif

struct DMACTRL_BITS {
    Uint16 HARDRESET:1;
    Uint16 PRIORITYRESET:1;
    Uint16 rsvd1:14;
};
union DMACTRL_REG {
    Uint16 all;
    struct DMACTRL_BITS bit;
};

struct DEBUGCTRL_BITS {
    Uint16 rsvd1:15;
    Uint16 FREE:1;
};
union DEBUGCTRL_REG {
    Uint16 all;
    struct DEBUGCTRL_BITS bit;
};

struct PRIORITYCTRL1_BITS {
    Uint16 CH1PRIORITY:1;
    Uint16 rsvd1:15;
};
union PRIORITYCTRL1_REG {
    Uint16 all;
    struct PRIORITYCTRL1_BITS bit;
};

struct PRIORITYSTAT_BITS {
    Uint16 ACTIVESTS:3;
    Uint16 rsvd1:1;
    Uint16 ACTIVESTS_SHADOW:3;
    Uint16 rsvd2:9;
};
union PRIORITYSTAT_REG {
    Uint16 all;
    struct PRIORITYSTAT_BITS bit;
};

struct MODE_BITS {
    Uint16 PERINTSEL:5;
    Uint16 rsvd1:2;
    Uint16 OVRINTE:1;
    Uint16 PERINTE:1;
    Uint16 CHINTMODE:1;
    Uint16 ONESHOT:1;
    Uint16 CONTINUOUS:1;
    Uint16 SYNCE:1;
    Uint16 SYNCSEL:1;
    Uint16 DATASIZE:1;
    Uint16 CHINTE:1;
};
union MODE_REG {
    Uint16 all;
    struct MODE_BITS bit;
};

struct CONTROL_BITS {
    Uint16 RUN:1;
    Uint16 HALT:1;
    Uint16 SOFTRESET:1;
    Uint16 PERINTFRC:1;
    Uint16 PERINTCLR:1;
    Uint16 SYNCFRC:1;
    Uint16 SYNCCLR:1;
    Uint16 ERRCLR:1;
    Uint16 PERINTFLG:1;
    Uint16 SYNCFLG:1;
    Uint16 SYNCERR:1;
    Uint16 TRANSFERSTS:1;
    Uint16 BURSTSTS:1;
    Uint16 RUNSTS:1;
    Uint16 OVRFLG:1;
    Uint16 rsvd1:1;
};
union CONTROL_REG {
    Uint16 all;
    struct CONTROL_BITS bit;
};

struct CH_REGS {
    union MODE_REG MODE; /* +0x00 */
    union CONTROL_REG CONTROL; /* +0x01 */
    Uint16 BURST_SIZE; /* +0x02 */
    Uint16 BURST_COUNT; /* +0x03 */
    Uint16 SRC_BURST_STEP; /* +0x04 */
    Uint16 DST_BURST_STEP; /* +0x05 */
    Uint16 TRANSFER_SIZE; /* +0x06 */
    Uint16 TRANSFER_COUNT; /* +0x07 */
    Uint16 SRC_TRANSFER_STEP; /* +0x08 */
    Uint16 DST_TRANSFER_STEP; /* +0x09 */
    Uint16 SRC_WRAP_SIZE; /* +0x0A */
    Uint16 SRC_WRAP_COUNT; /* +0x0B */
    Uint16 SRC_WRAP_STEP; /* +0x0C */
    Uint16 DST_WRAP_SIZE; /* +0x0D */
    Uint16 DST_WRAP_COUNT; /* +0x0E */
    Uint16 DST_WRAP_STEP; /* +0x0F */
    Uint32 SRC_BEG_ADDR_SHADOW; /* +0x10 */
    Uint32 SRC_ADDR_SHADOW; /* +0x12 */
    Uint32 SRC_BEG_ADDR_ACTIVE; /* +0x14 */
    Uint32 SRC_ADDR_ACTIVE; /* +0x16 */
    Uint32 DST_BEG_ADDR_SHADOW; /* +0x18 */
    Uint32 DST_ADDR_SHADOW; /* +0x1A */
    Uint32 DST_BEG_ADDR_ACTIVE; /* +0x1C */
    Uint32 DST_ADDR_ACTIVE; /* +0x1E */
};

struct DMA_REGS {
    union DMACTRL_REG DMACTRL; /* +0x00 */
    union DEBUGCTRL_REG DEBUGCTRL; /* +0x01 */
    Uint16 REVISION; /* +0x02 */
    Uint16 rsvd1[1];
    union PRIORITYCTRL1_REG PRIORITYCTRL1; /* +0x04 */
    Uint16 rsvd2[1];
    union PRIORITYSTAT_REG PRIORITYSTAT; /* +0x06 */
    Uint16 rsvd3[25];
    struct CH_REGS CH1; /* +0x20 */
    struct CH_REGS CH2; /* +0x40 */
    struct CH_REGS CH3; /* +0x60 */
    struct CH_REGS CH4; /* +0x80 */
    struct CH_REGS CH5; /* +0xA0 */
    struct CH_REGS CH6; /* +0xC0 */
};

extern volatile struct DMA_REGS DmaRegs;

#ifdef __cplusplus
}
#endif

#endif

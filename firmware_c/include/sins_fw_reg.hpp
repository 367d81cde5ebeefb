/* Register proxies of the replacement DSP2833x headers: each is an empty object whose address is part
   of its type, and whose reads and writes call the emulated board at that C28x address. A bit-field
   store is a read-modify-write of the whole 16-bit word, as the C28x does it. */
#ifndef SINS_FW_REG_HPP
#define SINS_FW_REG_HPP

#include <stdint.h>

/* The runtime (firmware_c/runtime/sins_fw_runtime.cpp): one 16-bit access at a C28x data address,
   charged its CPU cycles in virtual time. */
uint16_t sins_fw_read16(uint32_t address);
void sins_fw_write16(uint32_t address, uint16_t value);
/* DELAY_US: virtual time passes. */
void sins_fw_delay_us(double microseconds);
/* PieVectTable: set and read vector n (EALLOW-protected). */
void sins_fw_set_vector(unsigned n, void (*isr)(void));
void (*sins_fw_vector(unsigned n))(void);
/* The CPU's cregisters IER (0) and IFR (1). */
uint16_t sins_fw_creg_read(int which);
void sins_fw_creg_write(int which, uint16_t value);

/* A CPU core register (TI's `cregister`): IER or IFR. */
template <int W>
struct SinsCReg {
    operator uint16_t() const volatile { return sins_fw_creg_read(W); }
    uint16_t operator=(uint16_t v) volatile {
        sins_fw_creg_write(W, v);
        return v;
    }
    uint16_t operator|=(uint16_t v) volatile { return *this = static_cast<uint16_t>(sins_fw_creg_read(W) | v); }
    uint16_t operator&=(uint16_t v) volatile { return *this = static_cast<uint16_t>(sins_fw_creg_read(W) & v); }
};

/* A 16-bit register (`.all`, or a plain Uint16 member of TI's register struct). */
template <uint32_t A>
struct SinsReg16 {
    operator uint16_t() const volatile { return sins_fw_read16(A); }
    uint16_t operator=(uint16_t v) volatile {
        sins_fw_write16(A, v);
        return v;
    }
    uint16_t operator|=(uint16_t v) volatile { return *this = static_cast<uint16_t>(sins_fw_read16(A) | v); }
    uint16_t operator&=(uint16_t v) volatile { return *this = static_cast<uint16_t>(sins_fw_read16(A) & v); }
    uint16_t operator^=(uint16_t v) volatile { return *this = static_cast<uint16_t>(sins_fw_read16(A) ^ v); }
};

/* A 32-bit register (`.all`): two words, low word first. */
template <uint32_t A>
struct SinsReg32 {
    operator uint32_t() const volatile { return sins_fw_read16(A) | static_cast<uint32_t>(sins_fw_read16(A + 1)) << 16; }
    uint32_t operator=(uint32_t v) volatile {
        sins_fw_write16(A, static_cast<uint16_t>(v));
        sins_fw_write16(A + 1, static_cast<uint16_t>(v >> 16));
        return v;
    }
    uint32_t operator|=(uint32_t v) volatile { return *this = static_cast<uint32_t>(*this) | v; }
    uint32_t operator&=(uint32_t v) volatile { return *this = static_cast<uint32_t>(*this) & v; }
};

/* A bit field of W bits at bit L of the word at A (`.bit.X`). */
template <uint32_t A, unsigned L, unsigned W>
struct SinsField {
    static constexpr uint16_t MASK = static_cast<uint16_t>(((1u << W) - 1u) << L);
    operator uint16_t() const volatile { return static_cast<uint16_t>((sins_fw_read16(A) & MASK) >> L); }
    uint16_t operator=(uint16_t v) volatile {
        uint16_t word = sins_fw_read16(A);
        sins_fw_write16(A, static_cast<uint16_t>((word & ~MASK) | ((v << L) & MASK)));
        return v;
    }
};

/* A bit field of a 32-bit register, by its bit number (0…31): in the word that holds it. */
template <uint32_t A, unsigned BIT, unsigned W = 1>
using SinsField32 = SinsField<A + BIT / 16, BIT % 16, W>;

#endif

/* SPI-A FIFO loopback example: prototypes and settings. */
#ifndef SPI_LOOPBACK_H
#define SPI_LOOPBACK_H

#define LOOPBACK_BRR 0x007F /* LSPCLK / 128 */

void spi_fifo_init(void);
void spi_init(void);
void spi_xmit(Uint16 word);
void error(void);

#endif

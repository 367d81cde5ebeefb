; DSP28x_usDelay (placeholder: the host build skips assembly; the runtime provides the function).

"""gyroctl: the host side of the gyro's tuning UART (command line + telemetry frames).

Modules
    frames   COBS / CRC-16 frames and the text/frame receiver (mirrors tools/tlm_decode)
    link     a serial port (device, pty or pyserial URL) speaking the command-line protocol
    client   parameter and command helpers over a link (get, set, list, fields, ...)
    logger   `log`: a telemetry stream to CSV
    plot     `plot`: a CSV log to PNG
    shell    `shell`: interactive command line with tab completion
    load_params  `load-params`: a parameter set file (docs/param-set.md) into flash
    cli      the `gyroctl` command (tools/gyroctl)
"""

"""Hardware layer: CN3 codec, transports, client, and the drives (real and simulated) behind one interface."""

"""The guided procedures in the GUI: a stepper page driving the procedure engine, the sensor-dog
wizard panel, and the commissioning report as PDF (Qt's own printing)."""

"""The one physics model of an FHA-C axis, used by the simulated drive and by the model check."""

"""The actuator catalogue of the FHA-C manual (Chapter 1, 2 and 4), loaded from resources/catalog."""

"""Training on the simulated drive: scenarios with hidden faults (:mod:`.scenario`), the check
that each fault shows (:mod:`.check`), and the trainee's score sheet (:mod:`.score`, :mod:`.sheet`).
docs/training.md describes the scenario files."""

"""Names the bench tuning's command line offers before any of its work is imported (the numerical
modules take seconds to import; ``fha-studio --help`` must not wait for them)."""

#: the excitation's forms (:mod:`.bench_excitation`)
EXCITATION_FORMS = ("multisine", "prbs", "chirp")
#: the signals of a frequency response from the bench (:mod:`.bench_session`)
RESPONSE_ROLES = ("speed_monitor", "speed_command")
#: the signals of a move from the bench (a position-mode move by the controller's command pulses)
MOVE_ROLES = ("encoder_a", "encoder_b", "command_a", "command_b", "speed_monitor", "in_position")
#: every signal ``tune analyse`` takes
ANALYSE_ROLES = ("speed_monitor", "speed_command", "encoder_a", "encoder_b", "command_a", "command_b",
                 "in_position")

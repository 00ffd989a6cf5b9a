"""Names the bench tuning's command line offers before any of its work is imported (the numerical
modules take seconds to import; ``fha-studio --help`` must not wait for them)."""

#: the excitation's forms (:mod:`.bench_excitation`)
EXCITATION_FORMS = ("multisine", "prbs", "chirp")
#: the signals of a frequency response from the bench (:mod:`.bench_session`)
RESPONSE_ROLES = ("speed_monitor", "speed_command")

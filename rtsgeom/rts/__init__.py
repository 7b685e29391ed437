"""The RTS's channels (stage 3): each channel re-transmits the RuT's chirp with a programmed
delay (range), Doppler shift (velocity) and amplitude (RCS); its echoes per virtual element."""

from .channels import (Echoes, EchoKind, RtsProgram, build_echoes, cable_ghosts, channel_echoes,
                       program_nearest, setup_echoes, target_amplitude)
from .fir import (FirTaps, fir_error_response, fir_if_gain, fir_modelled, fir_taps,
                  fractional_delay_fir, realised_delay)

__all__ = ["RtsProgram", "EchoKind", "Echoes", "realised_delay", "target_amplitude",
           "channel_echoes", "setup_echoes", "cable_ghosts", "program_nearest", "build_echoes",
           "fractional_delay_fir", "fir_error_response", "fir_if_gain", "FirTaps", "fir_taps",
           "fir_modelled"]

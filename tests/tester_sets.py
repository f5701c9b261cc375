"""Parameter sets the black-box testers wrote, as they wrote them (shared by the tests that reproduce their runs)."""

#: tester O's gel (8 wt% gelatin on glass, guessed): Vc = 87.86 um/s
TESTER_GEL = """\
name = "my-gel-8pct"
description = "8 wt% gelatin on glass, my rig (guesses)"

[bonds]
site_density = "1.5e14 1/m^2"
bond_time = "300 us"
breakage_weight = 1.0
chain_stiffness = "1.2e-4 N/m"
activation_length = "1 angstrom"
temperature = "295 K"
max_extension = "1.0 um"

[aging]
aging_time = "1.2 ms"
aging_velocity = "300 um/s"

[stick]
attached_chains = "2.5e12 1/m^2"
break_rate = "2e-4 1/s"
aging_time = "8 s"

[block]
shear_modulus = "8 kPa"
height = "8 mm"
top_length = "40 mm"
base_length = "25 mm"
"""

"""Model families: the device (Harvester), friction laws, excitations, presets."""

# The sum of inputs registers its constructors in randvib.models.composition, which
# ``+`` on excitations and tones reads: loading it with the package makes the
# registry complete whichever model module is imported first.
from randvib.models import combined  # noqa: E402, F401

"""Design for a vibration: the harvester that harvests most under a stroke budget (:func:`randvib.design`)."""

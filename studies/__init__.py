"""The study scripts, installed with randvib as the package ``randvib.study_scripts``.

This folder is the scripts' one home: ``pyproject.toml`` maps it into the
package, so ``randvib study NAME`` finds ``NAME.py`` here in a checkout, an
editable install and an installed wheel alike (:func:`randvib.studies.load`).
Each script also runs on its own: ``python studies/NAME.py OUT_DIR [options]``.
"""

"""Packaged studies, one module each; see ``randvib.cli.study.STUDIES``."""

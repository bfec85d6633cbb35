"""Panel dashboard for the bogie model (a thin layer over :mod:`model`)."""

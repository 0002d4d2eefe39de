"""``python -m dtsp_mission.cli`` runs the same CLI as the ``dtsp-mission`` script."""

from .main import cli

cli(prog_name="dtsp-mission")

# SPDX-License-Identifier: BSD-3-Clause
"""`python3 -m vtkffd`: the command line of vtkffd.command_line."""
import sys

from vtkffd.command_line import main

sys.exit(main())

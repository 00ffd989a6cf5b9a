"""Entry script of the PyInstaller bundle: the same as the `fha-studio` console script."""

from fha_studio.main import main

raise SystemExit(main())

from fha_studio.main import main

raise SystemExit(main())

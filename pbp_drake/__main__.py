from pbp_drake.cli import main

raise SystemExit(main())

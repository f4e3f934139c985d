! irsig LOWTRAN-7 driver: runs LWTRN7 in card mode (reads ./TAPE5, writes
! out/TAPE6..8) and dumps the per-wavenumber results at full precision to
! ./result.txt (the formatted TAPE7 keeps only 3 significant digits).
! Columns: V [cm-1], TX9 (transmittance), SUMVV (thermal path radiance,
! W cm-2 sr-1 / cm-1), TSOLIL (transmitted solar irradiance, W cm-2 um-1),
! SOLIL (exo-atmospheric solar irradiance, W cm-2 um-1), SUMSSR (solar
! scattered path radiance, W cm-2 sr-1 / cm-1).
program ltdrv
  implicit none
  integer, parameter :: nw = 4000
  real :: tx(nw, 63), v(nw), al(nw), tr(nw), un(nw), sa(nw), irr(nw, 3), svv(nw)
  real :: zm(1), p(1), t(1), wm(12)
  integer :: i
  v = -1.0
  irr = 0.0
  svv = 0.0
  zm = 0.0; p = 0.0; t = 0.0; wm = 0.0
  call lwtrn7(.false., nw, 0.0, 0.0, 0.0, tx, v, al, tr, un, sa, irr, svv, &
              0, 0, 0, 0, 0, 1, 0, zm, p, t, wm, 0.0, 0.0, 0.0, 0.0)
  open (20, file='result.txt', status='replace')
  do i = 1, nw
    if (v(i) < 0.0) exit
    write (20, '(F9.1,5ES16.8)') v(i), tx(i, 1), svv(i), irr(i, 1), irr(i, 2), irr(i, 3)
  end do
  close (20)
end program ltdrv

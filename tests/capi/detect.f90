! A Fortran program using the detector through the `tethash` module, on the scene of detect.c, checked against the
! result worked out by hand there: vertex 8 (0-based 7) at (0.2, 0.2, 0.1) inside tet 1 (0-based 0), barycentric
! (0.5, 0.2, 0.2, 0.1), penetration depth 0.1 along -z, and the three edge-face contacts of the edges into it; no
! contact after the caller moves it to z = -0.1; moved back up over a step, continuous detection finds it passing
! through tet 1's base at t = 0.5, unless a locality rule makes the pair local.
! Stops with status 1 on any failure.
program detect_fortran
  use, intrinsic :: iso_c_binding
  use tethash
  implicit none
  real(c_double), target :: x(3, 8)
  integer(c_int32_t) :: tets(4, 2)
  integer(c_int32_t), target :: vertex_object(8), tet_object(2)
  integer(c_int32_t) :: vertex(1), tet(1)
  real(c_double) :: bary(4, 1), depth(1), direction(3, 1)
  type(c_ptr) :: d
  integer(c_int64_t) :: count
  type(tethash_contact) :: c
  type(tethash_stats) :: stats
  integer :: failures
  real(c_double) :: ccd_start(3, 4), ccd_end(3, 4), toi
  integer(c_int32_t) :: hit
  integer(c_int32_t) :: edge(2, 3), inner_end(3)
  real(c_double) :: t(3), normal(3, 3)
  real(c_double) :: x_end(3, 8), cont_toi(1)
  integer(c_int32_t) :: kind(1), ids(4, 1)
  integer(c_int32_t) :: group(8)
  integer(c_int64_t) :: pairs

  failures = 0
  x = reshape([0d0, 0d0, 0d0, 1d0, 0d0, 0d0, 0d0, 1d0, 0d0, 0d0, 0d0, 1d0, &
               0d0, 0d0, -1d0, 1d0, 0d0, -1d0, 0d0, 1d0, -1d0, 0.2d0, 0.2d0, 0.1d0], [3, 8])
  tets = reshape([0, 1, 2, 3, 4, 5, 6, 7], [4, 2]) ! 0-based vertex indices
  vertex_object = [0, 0, 0, 0, 1, 1, 1, 1]
  tet_object = [0, 1]

  call ok(tethash_detector_create(d), "create")
  call ok(tethash_detector_set_threads(d, 1_c_int32_t), "set_threads")
  ! Enumerations are int32 on both sides: the module's constants pass as they are.
  call ok(tethash_detector_set_hash(d, TETHASH_HASH_TESCHNER), "set_hash")
  call ok(tethash_detector_set_cell_size(d, TETHASH_CELL_SIZE_AUTO, 1d0), "set_cell_size")
  call expect(tethash_detector_set_hash(d, 7_c_int32_t) == TETHASH_ERROR_INVALID_ARGUMENT, "hash 7 refused")
  call ok(tethash_detector_set_topology(d, tets, 2_c_int64_t, 8_c_int64_t, c_loc(vertex_object), &
                                        c_loc(tet_object)), "set_topology")
  call ok(tethash_detector_detect(d, x, 8_c_int64_t, count), "detect")
  call expect(count == 1, "one contact")
  call ok(tethash_detector_compute_penetration(d, x, 8_c_int64_t), "compute_penetration")
  call ok(tethash_detector_get_contacts(d, 1_c_int64_t, vertex, tet, bary, depth, direction), "get_contacts")
  ! List-directed output only: libgfortran reads a format string past its end (a false report under ASan).
  print *, 'contact vertex', vertex(1), 'tet', tet(1), 'bary', bary(:, 1), 'depth', depth(1), 'direction', &
    direction(:, 1)
  call expect(vertex(1) == 7 .and. tet(1) == 0, "vertex 7 in tet 0")
  call expect(all(abs(bary(:, 1) - [0.5d0, 0.2d0, 0.2d0, 0.1d0]) < 1d-12), "bary")
  call expect(abs(depth(1) - 0.1d0) < 1d-12, "depth 0.1")
  call expect(all(abs(direction(:, 1) - [0d0, 0d0, -1d0]) < 1d-12), "direction -z")
  ! Optional outputs may be left out.
  call ok(tethash_detector_get_contacts(d, 1_c_int64_t, tet=tet), "get_contacts (tet only)")
  call ok(tethash_detector_contact(d, 0_c_int64_t, c), "contact 0")
  call expect(c%vertex == 7 .and. c%tet_object == 0 .and. c%vertex_object == 1, "contact record")

  call ok(tethash_detector_stats(d, stats), "stats")
  call expect(stats%contacts == 1 .and. stats%threads == 1 .and. stats%cell_size > 0, "stats")

  ! Errors come back as a status and a message.
  call expect(tethash_detector_detect(d, x, 7_c_int64_t, count) == TETHASH_ERROR_INVALID_ARGUMENT, "wrong size refused")
  call expect(index(tethash_error_message(), "num_vertices") > 0, "message names num_vertices")
  print *, 'expected error: ', tethash_error_message()

  ! Edge-face contacts: the edges 4-7, 5-7, 6-7 enter tet 0 through its base z = 0, 1 / 1.1 of the way along.
  call ok(tethash_detector_find_edge_contacts(d, x, 8_c_int64_t, count), "find_edge_contacts")
  call expect(count == 3, "three edge-face contacts")
  if (count == 3) then
    call ok(tethash_detector_get_edge_contacts(d, 3_c_int64_t, edge=edge, t=t, inner_end=inner_end, normal=normal), &
            "get_edge_contacts")
    call expect(all(edge(1, :) == [4, 5, 6]) .and. all(edge(2, :) == 7), "edges 4-7, 5-7, 6-7")
    call expect(all(abs(t - 1d0 / 1.1d0) < 1d-12) .and. all(inner_end == 1), "t and inner end")
    call expect(all(abs(normal(3, :) + 1d0) < 1d-12), "normal -z")
  end if

  ! The caller moves its own array; the next detection reads it in place.
  x(3, 8) = -0.1d0
  call ok(tethash_detector_detect(d, x, 8_c_int64_t, count), "detect after the move")
  call expect(count == 0, "no contact after the move")

  ! Continuous detection over a step: vertex 8 back from z = -0.1 to 0.1 passes through tet 1's base at t = 0.5.
  x_end = x
  x_end(3, 8) = 0.1d0
  call ok(tethash_detector_detect_continuous(d, x, x_end, 8_c_int64_t, 1d-6, 1000000_c_int64_t, count), &
          "detect_continuous")
  call expect(count == 1, "one continuous contact")
  if (count == 1) then
    call ok(tethash_detector_get_continuous_contacts(d, 1_c_int64_t, kind=kind, vertices=ids, toi=cont_toi), &
            "get_continuous_contacts")
    call expect(kind(1) == 0 .and. ids(1, 1) == 7, "vertex 7 (0-based) against a face")
    call expect(sum(ids(2:4, 1)) == 3 .and. product(ids(2:4, 1)) == 0, "the face 0 1 2")
    call expect(cont_toi(1) <= 0.5d0 .and. cont_toi(1) > 0.4999d0, "at t = 0.5")
  end if
  ! The locality rule: vertex 8 lies 0.3 from vertex 1 (the face's corner) in x_end (the rest state here). One group
  ! with a squared reach of 0.25 makes the pair local and leaves it out, though the grid met it; 0.0025 makes it far.
  group = 0
  call ok(tethash_detector_set_continuous_locality(d, x_end, 8_c_int64_t, group, [0.25d0], 1_c_int64_t), &
          "set_continuous_locality")
  call ok(tethash_detector_detect_continuous(d, x, x_end, 8_c_int64_t, 1d-6, 1000000_c_int64_t, count), &
          "detect_continuous with the rule")
  call expect(count == 0, "a local pair left out")
  call ok(tethash_detector_continuous_broad_phase_pairs(d, pairs), "continuous_broad_phase_pairs")
  call expect(pairs >= 1, "the grid met the local pair")
  call ok(tethash_detector_set_continuous_locality(d, x_end, 8_c_int64_t, group, [0.0025d0], 1_c_int64_t), &
          "set_continuous_locality, narrow")
  call ok(tethash_detector_detect_continuous(d, x, x_end, 8_c_int64_t, 1d-6, 1000000_c_int64_t, count), &
          "detect_continuous with the narrow rule")
  call expect(count == 1, "a far pair found")

  call tethash_detector_destroy(d)

  ! A continuous query: the vertex from (0.2, 0.2, 1) to (0.2, 0.2, -1) through the still triangle meets it at 0.5.
  ccd_start = reshape([0.2d0, 0.2d0, 1d0, 0d0, 0d0, 0d0, 1d0, 0d0, 0d0, 0d0, 1d0, 0d0], [3, 4])
  ccd_end = ccd_start
  ccd_end(3, 1) = -1d0
  call ok(tethash_ccd_vertex_face(ccd_start, ccd_end, 1d-6, 1000000_c_int64_t, hit, toi), "ccd_vertex_face")
  call expect(hit == 1 .and. toi <= 0.5d0 .and. toi > 0.4999d0, "vertex meets the triangle at t = 0.5")
  if (failures > 0) then
    print *, 'FAILED'
    stop 1
  end if
  print *, 'ok'

contains

  subroutine ok(status, what)
    integer(c_int), intent(in) :: status
    character(len=*), intent(in) :: what
    if (status /= TETHASH_OK) then
      print *, 'FAILED: ', what, ': ', tethash_error_message()
      failures = failures + 1
    end if
  end subroutine ok

  subroutine expect(cond, what)
    logical, intent(in) :: cond
    character(len=*), intent(in) :: what
    if (.not. cond) then
      print *, 'FAILED: ', what
      failures = failures + 1
    end if
  end subroutine expect

end program detect_fortran
